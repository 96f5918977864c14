// A rosbag as a StereoSource (`planeloc run --bag`): rectified stereo images on two topics
// (sensor_msgs/Image mono8/rgb8/bgr8, or sensor_msgs/CompressedImage), their rectified camera
// info (sensor_msgs/CameraInfo: intrinsics and baseline from P), paired by header stamp.
//
// Open reads every image message once for its header stamp (the images are decoded only when a
// frame is loaded); pairs are a left and a right stamp within `pair_tolerance` of each other, in
// order; images without a partner are counted and warned about. Every error is an InputError
// naming the bag and topic: a missing topic, a topic of another type, an unsupported encoding,
// unrectified camera info, stamps that go back in time.
//
// This header includes no ROS header: ROS 1 messages do not compile as C++20 (their allocators
// use std::allocator<void>::rebind), so the module is compiled as C++17 and the C++20 code of
// planeloc (the CLI) sees only this interface.
#pragma once

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/io/stereo_source.h"

namespace planeloc::ros {

struct BagOptions {
  std::string left_topic;  // sensor_msgs/Image or sensor_msgs/CompressedImage
  std::string right_topic;
  // sensor_msgs/CameraInfo; empty: the image topic's namespace + "/camera_info"
  // (/stereo/left/image_rect -> /stereo/left/camera_info).
  std::string left_info_topic;
  std::string right_info_topic;
  // A left and a right image whose header stamps differ by at most this much (seconds) are one
  // stereo frame. Hardware-synchronized stereo drivers stamp both alike.
  double pair_tolerance = 0.005;
  // The image topics carry rectified images although the camera info has D and R of the raw
  // camera (image_rect with the raw camera_info); P is used either way.
  bool assume_rectified = false;
  // Throws OptionsError naming the field.
  void Check() const;
};

// The default camera-info topic of an image topic: its namespace + "/camera_info".
std::string CameraInfoTopicFor(const std::string& image_topic);

class BagSequence : public StereoSource {
 public:
  static std::unique_ptr<BagSequence> Open(const std::filesystem::path& bag,
                                           const BagOptions& options);
  ~BagSequence() override;

  std::string name() const override;
  std::size_t size() const override;
  const StereoCamera& camera() const override;
  // Header stamp of the left image (seconds since the epoch of the bag's clock).
  double timestamp(std::size_t index) const override;
  StereoPair LoadStereoPair(std::size_t index) const override;

  // Images on each topic without a partner within the tolerance.
  int unpaired_left() const;
  int unpaired_right() const;
  // With the camera-info topics filled in.
  const BagOptions& options() const;

 private:
  struct Impl;
  explicit BagSequence(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace planeloc::ros
