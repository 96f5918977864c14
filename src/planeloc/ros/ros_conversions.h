// Between ROS 1 messages and planeloc's types: sensor_msgs/CameraInfo <-> StereoCamera, and
// sensor_msgs/Image or CompressedImage -> a grey cv::Mat. Errors are InputError naming the topic
// (as the `path`), so that `planeloc run --bag` and planeloc_node say which topic is wrong.
#pragma once

#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>

#include <opencv2/core.hpp>
#include <string>

#include "planeloc/geometry/camera.h"

namespace planeloc::ros {

// The rectified stereo camera of a left/right CameraInfo pair, from their projection matrices P
// (fx, fy, cx, cy of the left one; baseline = -P_right(0,3) / fx). InputError naming the topic
// when P is unset (all zero: an uncalibrated camera), the two P disagree on the intrinsics, the
// right P has no baseline (not a rectified pair), the sizes differ, or (unless
// `assume_rectified`) a distortion D or rectification R is set: the info describes raw images.
StereoCamera StereoCameraFromInfo(const sensor_msgs::CameraInfo& left,
                                  const sensor_msgs::CameraInfo& right,
                                  const std::string& left_topic, const std::string& right_topic,
                                  bool assume_rectified = false);
// CameraInfo of the rectified left (right = false) or right camera: D = 0 (plumb_bob), R = I,
// K and P from `camera` (right: P(0,3) = -fx * baseline).
sensor_msgs::CameraInfo CameraInfoFromStereo(const StereoCamera& camera, bool right);

// Encodings the bag input and the node accept: mono8, rgb8, bgr8 (also rgba8, bgra8).
bool IsSupportedEncoding(const std::string& encoding);
// A grey CV_8UC1 copy of the image. InputError naming the topic for another encoding or a
// malformed message.
cv::Mat GreyImage(const sensor_msgs::Image& image, const std::string& topic);
// Decoded through cv_bridge (png, jpeg, ... as OpenCV reads them), then grey.
cv::Mat GreyImage(const sensor_msgs::CompressedImage& image, const std::string& topic);

}  // namespace planeloc::ros
