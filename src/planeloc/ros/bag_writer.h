// Writes a stereo source (a KITTI-layout folder) as a rosbag that `planeloc run --bag` and
// planeloc_node read: `planeloc convert kitti-to-bag`. Per frame a left and a right image with
// the same header stamp (start_time + the source's timestamp), and the rectified camera info of
// each camera (D = 0, R = I, P with the baseline) on <image namespace>/camera_info.
#pragma once

#include <filesystem>
#include <string>

#include "planeloc/io/stereo_source.h"

namespace planeloc::ros {

struct BagWriteOptions {
  std::string left_topic = "/stereo/left/image_rect";
  std::string right_topic = "/stereo/right/image_rect";
  // mono8 | rgb8 | bgr8 (sensor_msgs/Image) | png | jpeg (sensor_msgs/CompressedImage).
  std::string encoding = "mono8";
  std::string frame_id = "camera";  // header.frame_id of images and camera info
  double start_time = 1000.0;       // seconds added to the source's timestamps (ROS time > 0)
  int max_frames = 0;               // 0: all
  // Throws OptionsError naming the field.
  void Check() const;
};

// Returns the number of frames written. The bag is written beside `bag` and renamed onto it when
// complete. Throws InputError naming the frame's file or the bag.
int WriteStereoBag(const StereoSource& source, const std::filesystem::path& bag,
                   const BagWriteOptions& options);

}  // namespace planeloc::ros
