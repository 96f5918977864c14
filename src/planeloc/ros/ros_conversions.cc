#include "planeloc/ros/ros_conversions.h"

#include <cv_bridge/cv_bridge.h>
#include <fmt/format.h>
#include <sensor_msgs/distortion_models.h>
#include <sensor_msgs/image_encodings.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "planeloc/util/error.h"

namespace planeloc::ros {
namespace {

constexpr char kRectifiedFix[] =
    "record rectified images with their rectified camera info (P set, D = 0, R = I; e.g. "
    "image_rect of stereo_image_proc, or `planeloc convert kitti-to-bag`)";

bool Near(double a, double b) { return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(a)); }

// P set, D zero, R identity; `topic` in the errors.
void CheckRectifiedInfo(const sensor_msgs::CameraInfo& info, const std::string& topic,
                        bool assume_rectified) {
  CheckInput(info.P[0] > 0 && info.P[5] > 0 && info.P[10] == 1.0, topic, 0,
             fmt::format("the camera info has no rectified projection matrix P (fx {}, fy {})",
                         info.P[0], info.P[5]),
             kRectifiedFix);
  CheckInput(info.width > 0 && info.height > 0, topic, 0,
             "the camera info gives no image size (width, height 0)", kRectifiedFix);
  if (assume_rectified) return;
  const bool distorted = std::any_of(info.D.begin(), info.D.end(), [](double d) { return d != 0; });
  bool rotated = false;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) rotated |= !Near(info.R[r * 3 + c], r == c ? 1.0 : 0.0);
  }
  CheckInput(!distorted && !rotated, topic, 0,
             fmt::format("the camera info describes unrectified images ({}{}{})",
                         distorted ? "distortion D set" : "", distorted && rotated ? ", " : "",
                         rotated ? "rectification R not identity" : ""),
             std::string(kRectifiedFix) +
                 ", or pass --assume-rectified when the image topics carry rectified images and "
                 "the camera info is the raw camera's");
}

}  // namespace

StereoCamera StereoCameraFromInfo(const sensor_msgs::CameraInfo& left,
                                  const sensor_msgs::CameraInfo& right,
                                  const std::string& left_topic, const std::string& right_topic,
                                  bool assume_rectified) {
  CheckRectifiedInfo(left, left_topic, assume_rectified);
  CheckRectifiedInfo(right, right_topic, assume_rectified);
  const bool same = Near(left.P[0], right.P[0]) && Near(left.P[5], right.P[5]) &&
                    Near(left.P[2], right.P[2]) && Near(left.P[6], right.P[6]);
  CheckInput(same, right_topic, 0,
             fmt::format("the right camera's P (fx {}, fy {}, cx {}, cy {}) differs from the "
                         "left's on {} (fx {}, fy {}, cx {}, cy {}): not a rectified pair",
                         right.P[0], right.P[5], right.P[2], right.P[6], left_topic, left.P[0],
                         left.P[5], left.P[2], left.P[6]),
             kRectifiedFix);
  CheckInput(left.width == right.width && left.height == right.height, right_topic, 0,
             fmt::format("the right camera is {}x{}, the left on {} {}x{}", right.width,
                         right.height, left_topic, left.width, left.height),
             kRectifiedFix);
  StereoCamera camera;
  camera.fx = left.P[0];
  camera.fy = left.P[5];
  camera.cx = left.P[2];
  camera.cy = left.P[6];
  // Only the relative offset defines the baseline (the left P may carry its own, as KITTI's).
  camera.baseline = (left.P[3] - right.P[3]) / camera.fx;
  camera.width = static_cast<int>(left.width);
  camera.height = static_cast<int>(left.height);
  CheckInput(camera.baseline > 0 && std::isfinite(camera.baseline), right_topic, 0,
             fmt::format("the right camera's P(0,3) = {} gives no positive baseline (left P(0,3) "
                         "= {}): not a rectified stereo pair, or left and right swapped",
                         right.P[3], left.P[3]),
             "give the right camera's info with P(0,3) = -fx * baseline (ROS stereo convention), "
             "or swap --left-topic and --right-topic");
  return camera;
}

sensor_msgs::CameraInfo CameraInfoFromStereo(const StereoCamera& camera, bool right) {
  sensor_msgs::CameraInfo info;
  info.width = camera.width;
  info.height = camera.height;
  info.distortion_model = sensor_msgs::distortion_models::PLUMB_BOB;
  info.D.assign(5, 0.0);
  info.K = {camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1};
  info.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double tx = right ? -camera.fx * camera.baseline : 0.0;
  info.P = {camera.fx, 0, camera.cx, tx, 0, camera.fy, camera.cy, 0, 0, 0, 1, 0};
  return info;
}

bool IsSupportedEncoding(const std::string& encoding) {
  namespace enc = sensor_msgs::image_encodings;
  return encoding == enc::MONO8 || encoding == enc::RGB8 || encoding == enc::BGR8 ||
         encoding == enc::RGBA8 || encoding == enc::BGRA8;
}

cv::Mat GreyImage(const sensor_msgs::Image& image, const std::string& topic) {
  CheckInput(IsSupportedEncoding(image.encoding), topic, 0,
             fmt::format("image encoding \"{}\" is not supported", image.encoding),
             "publish mono8, rgb8 or bgr8 images (or sensor_msgs/CompressedImage)");
  try {
    return cv_bridge::toCvCopy(image, sensor_msgs::image_encodings::MONO8)->image;
  } catch (const cv_bridge::Exception& e) {
    throw InputError(topic, 0, fmt::format("cannot convert the image: {}", e.what()),
                     "check the message's width, height, step and data size");
  }
}

cv::Mat GreyImage(const sensor_msgs::CompressedImage& image, const std::string& topic) {
  cv::Mat decoded;
  try {
    decoded = cv_bridge::toCvCopy(image, sensor_msgs::image_encodings::MONO8)->image;
  } catch (const std::exception& e) {  // cv_bridge::Exception or cv::Exception
    throw InputError(topic, 0,
                     fmt::format("cannot decode the compressed image (format \"{}\"): {}",
                                 image.format, e.what()),
                     "compress with png or jpeg (image_transport's compressed plugin)");
  }
  CheckInput(!decoded.empty() && decoded.type() == CV_8UC1, topic, 0,
             fmt::format("the compressed image (format \"{}\") did not decode to 8-bit grey",
                         image.format),
             "compress 8-bit mono or colour images with png or jpeg");
  return decoded;
}

}  // namespace planeloc::ros
