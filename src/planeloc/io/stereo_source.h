// A source of rectified stereo frames for the tracker: a KITTI-layout folder (kitti_sequence.h)
// or a rosbag (ros/bag_sequence.h, built with ROS). RunSequence (`planeloc run`) reads frames
// through this interface only.
#pragma once

#include <cstddef>
#include <opencv2/core.hpp>
#include <string>

#include "planeloc/geometry/camera.h"

namespace planeloc {

struct StereoPair {
  cv::Mat left;   // CV_8UC1, rectified
  cv::Mat right;  // CV_8UC1, rectified, same size as left
};

class StereoSource {
 public:
  virtual ~StereoSource() = default;
  // The folder or file the frames come from (for messages).
  virtual std::string name() const = 0;
  virtual std::size_t size() const = 0;
  // The rectified stereo camera of every frame.
  virtual const StereoCamera& camera() const = 0;
  // Where camera() comes from (a calibration file, for messages); name() when not a file.
  virtual std::string calibration_name() const { return name(); }
  // Seconds (the source's clock), increasing.
  virtual double timestamp(std::size_t index) const = 0;
  // Decodes frame `index`. Throws InputError naming the file or topic when it cannot. RunSequence
  // calls it on worker threads while the current frame is tracked, for two frames at once: it
  // must be safe to call concurrently with itself and with the other methods.
  virtual StereoPair LoadStereoPair(std::size_t index) const = 0;
  // False when the frame's images are known to be missing; then MissingFrame says which.
  virtual bool HasFrame(std::size_t index) const {
    (void)index;
    return true;
  }
  virtual std::string MissingFrame(std::size_t index) const {
    (void)index;
    return "";
  }
};

}  // namespace planeloc
