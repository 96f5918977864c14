// The planeloc side of planeloc_node, behind types that both language levels read: the node's ROS
// code is C++17 (ROS 1 messages do not compile as C++20, see ros/bag_sequence.h) and planeloc's
// Localizer is C++20, so this header holds only std and OpenCV types.
#pragma once

#include <array>
#include <memory>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace planeloc::node {

struct NodeConfig {
  std::string planes_path;    // planes.json; empty: visual odometry
  std::string settings_path;  // settings YAML (tracker keys); empty: defaults
  // Row-major 3x4 world_from_cam of the first frame, in the plane map's frame.
  std::array<double, 12> initial_pose{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
  // S_XY (m), S_Z (m), S_YAW (deg): how well initial_pose is known; zeros: exact.
  std::array<double, 3> init_sigma{0, 0, 0};
  bool deterministic = false;
};

struct NodeCamera {
  double fx = 0, fy = 0, cx = 0, cy = 0, baseline = 0;
  int width = 0, height = 0;
};

struct NodeFrame {
  std::array<double, 3> translation{};  // world_from_cam
  std::array<double, 4> rotation{};     // x, y, z, w
  std::string state;                    // tracking | lost | relocalized
  std::string map_lock;                 // searching | partial | locked | "" (no plane map)
  bool keyframe = false;
  bool localized = false;
  int tracked_points = 0;
};

// A plane of the map as a closed outline in the map frame (for visualization markers).
struct NodePlane {
  int id = 0;
  std::vector<std::array<double, 3>> outline;
};

// Throws planeloc::InputError naming the file.
std::vector<NodePlane> ReadPlaneOutlines(const std::string& planes_path);

class NodeLocalizer {
 public:
  // Reads the plane map and settings; throws planeloc::InputError / OptionsError.
  NodeLocalizer(const NodeConfig& config, const NodeCamera& camera);
  ~NodeLocalizer();
  NodeLocalizer(const NodeLocalizer&) = delete;
  NodeLocalizer& operator=(const NodeLocalizer&) = delete;
  // Grey rectified images of the camera's size.
  NodeFrame Track(const cv::Mat& left, const cv::Mat& right, double stamp);
  void Finish();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace planeloc::node
