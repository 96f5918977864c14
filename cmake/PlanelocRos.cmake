# ROS 1 (Debian 12's Noetic-generation packages, scripts/setup.sh installs them): rosbag input of
# `planeloc run --bag` and `planeloc convert kitti-to-bag` (module src/planeloc/ros), and the
# planeloc_node (apps/ros). Off, with a message naming the missing packages, where they are absent.
# Sets PLANELOC_HAVE_ROS and the INTERFACE target planeloc_ros_deps (ROS headers as SYSTEM: they
# warn under -Wall -Wextra).
option(PLANELOC_WITH_ROS "Build rosbag input and planeloc_node when the ROS 1 packages are present"
       ON)
set(PLANELOC_HAVE_ROS OFF)
if(NOT PLANELOC_WITH_ROS)
  message(STATUS "planeloc: ROS off (PLANELOC_WITH_ROS=OFF): no rosbag input, no planeloc_node")
  return()
endif()
# The ROS CMake configs run Python helpers (catkin_pkg, ament_package via pluginlib) installed for
# Debian's python3: prefer it to another python3 first on PATH (e.g. pyenv's).
if(EXISTS /usr/bin/python3)
  if(NOT Python3_EXECUTABLE)
    set(Python3_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "python3 of the ROS packages")
  endif()
  if(NOT PYTHON_EXECUTABLE)
    set(PYTHON_EXECUTABLE /usr/bin/python3 CACHE FILEPATH "python3 of the ROS packages (catkin)")
  endif()
endif()
set(planeloc_ros_packages roscpp rosbag cv_bridge sensor_msgs std_msgs geometry_msgs nav_msgs
                          tf2_ros visualization_msgs message_filters)
set(planeloc_ros_missing "")
set(planeloc_ros_includes "")
set(planeloc_ros_libraries "")
foreach(pkg ${planeloc_ros_packages})
  find_package(${pkg} QUIET)
  if(${pkg}_FOUND)
    list(APPEND planeloc_ros_includes ${${pkg}_INCLUDE_DIRS})
    list(APPEND planeloc_ros_libraries ${${pkg}_LIBRARIES})
  else()
    list(APPEND planeloc_ros_missing ${pkg})
  endif()
endforeach()
if(planeloc_ros_missing)
  message(STATUS "planeloc: ROS 1 packages not found (${planeloc_ros_missing}): rosbag input "
                 "(planeloc run --bag, planeloc convert kitti-to-bag) and planeloc_node are OFF; "
                 "scripts/setup.sh installs them")
  return()
endif()
list(REMOVE_DUPLICATES planeloc_ros_includes)
add_library(planeloc_ros_deps INTERFACE)
target_include_directories(planeloc_ros_deps SYSTEM INTERFACE ${planeloc_ros_includes})
target_link_libraries(planeloc_ros_deps INTERFACE ${planeloc_ros_libraries})
find_program(PLANELOC_ROSMASTER rosmaster)
set(PLANELOC_HAVE_ROS ON)
message(STATUS "planeloc: ROS 1 found: rosbag input and planeloc_node are ON")
