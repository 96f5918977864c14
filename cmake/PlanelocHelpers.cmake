# planeloc_module(NAME name DEPS ... [TEST_DEPS ...] [SLOW_TESTS gtest-filter])
# One static library per folder of src/planeloc/: every *.cc that is not a *_test.cc belongs to it,
# every *_test.cc goes into one GoogleTest binary `planeloc_<name>_test`, registered as one ctest.
# SLOW_TESTS (a --gtest_filter pattern, e.g. "FooSimTest.*:BarSimTest.*") splits that ctest in
# two: `<name>` runs the rest, `<name>.slow` (labels <name> and slow) runs the matching tests. The
# sanitizer run in CI leaves the `slow` label out (docs/reliability.md, "Sanitizers").
# Every *_fuzz.cc is a libFuzzer target `planeloc_<file>` linked to the module, built only with
# PLANELOC_BUILD_FUZZ (scripts/fuzz.sh).
# Globbing (CONFIGURE_DEPENDS) lets a module grow a file without touching CMake.
# Every module library is installed and exported as `planeloc::<name>` (cmake/planelocConfig.cmake.in);
# in the build tree the same name is an alias, so the CLI and an installed consumer read alike.
function(planeloc_compile_flags target)
  target_compile_options(${target} PRIVATE -Wall -Wextra)
  if(PLANELOC_WERROR)
    target_compile_options(${target} PRIVATE -Werror)
  endif()
endfunction()

function(planeloc_module)
  # NO_INSTALL: a module left out of the installed package (the ROS one: its dependencies are
  # not exported).
  cmake_parse_arguments(ARG "NO_INSTALL" "NAME;SLOW_TESTS" "DEPS;TEST_DEPS" ${ARGN})
  set(dir ${CMAKE_CURRENT_SOURCE_DIR}/${ARG_NAME})
  file(GLOB srcs CONFIGURE_DEPENDS ${dir}/*.cc)
  file(GLOB tests CONFIGURE_DEPENDS ${dir}/*_test.cc)
  file(GLOB fuzzers CONFIGURE_DEPENDS ${dir}/*_fuzz.cc)
  if(tests)
    list(REMOVE_ITEM srcs ${tests})
  endif()
  if(fuzzers)
    list(REMOVE_ITEM srcs ${fuzzers})
  endif()
  set(target planeloc_${ARG_NAME})
  if(NOT srcs)
    # A module that has only headers so far.
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>
                                                   $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(${target} INTERFACE ${ARG_DEPS})
  else()
    add_library(${target} STATIC ${srcs})
    target_include_directories(${target} PUBLIC $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>
                                                $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(${target} PUBLIC ${ARG_DEPS})
    planeloc_compile_flags(${target})
  endif()
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${ARG_NAME})
  add_library(planeloc::${ARG_NAME} ALIAS ${target})
  if(NOT ARG_NO_INSTALL)
    install(TARGETS ${target} EXPORT planelocTargets
            ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
            LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
    # The module's headers, without the test fixtures (*_test.h, *for_test.h, test_*.h).
    install(DIRECTORY ${dir}/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/planeloc/${ARG_NAME}
            FILES_MATCHING PATTERN "*.h"
            PATTERN "*_test.h" EXCLUDE PATTERN "*for_test.h" EXCLUDE PATTERN "test_*.h" EXCLUDE)
  endif()
  if(PLANELOC_BUILD_FUZZ)
    foreach(fuzzer ${fuzzers})
      get_filename_component(fuzz_name ${fuzzer} NAME_WE)
      add_executable(planeloc_${fuzz_name} ${fuzzer})
      target_link_libraries(planeloc_${fuzz_name} PRIVATE ${target})
      target_compile_options(planeloc_${fuzz_name} PRIVATE -fsanitize=fuzzer-no-link)
      target_link_options(planeloc_${fuzz_name} PRIVATE -fsanitize=fuzzer)
      planeloc_compile_flags(planeloc_${fuzz_name})
    endforeach()
  endif()
  if(PLANELOC_BUILD_TESTS AND tests)
    add_executable(${target}_test ${tests})
    target_link_libraries(${target}_test PRIVATE ${target} ${ARG_TEST_DEPS} GTest::gtest
                          planeloc_test_main)
    target_compile_definitions(${target}_test PRIVATE
      PLANELOC_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
    planeloc_compile_flags(${target}_test)
    # One ctest per module binary, not per test: suites share expensive fixtures (a rendered
    # synthetic sequence) through SetUpTestSuite, which per-test processes would redo each time.
    if(ARG_SLOW_TESTS)
      add_test(NAME ${ARG_NAME} COMMAND ${target}_test --gtest_filter=-${ARG_SLOW_TESTS}
               WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
      add_test(NAME ${ARG_NAME}.slow COMMAND ${target}_test --gtest_filter=${ARG_SLOW_TESTS}
               WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
      set_tests_properties(${ARG_NAME}.slow PROPERTIES LABELS "${ARG_NAME};slow" TIMEOUT 1800)
    else()
      add_test(NAME ${ARG_NAME} COMMAND ${target}_test WORKING_DIRECTORY ${PROJECT_SOURCE_DIR})
    endif()
    set_tests_properties(${ARG_NAME} PROPERTIES LABELS ${ARG_NAME} TIMEOUT 900)
  endif()
endfunction()
