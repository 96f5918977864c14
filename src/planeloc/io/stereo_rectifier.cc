#include "planeloc/io/stereo_rectifier.h"

#include <fmt/format.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <vector>

namespace planeloc {
namespace {

void RequireShape(const cv::Mat& m, int rows, int cols, const char* name) {
  if (m.rows != rows || m.cols != cols || m.channels() != 1) {
    throw std::invalid_argument(fmt::format("StereoRectifier: {} must be {}x{}, got {}x{}", name,
                                            rows, cols, m.rows, m.cols));
  }
}

void RequireCamera(const RawCamera& camera, const char* name) {
  RequireShape(camera.k, 3, 3, name);
  const int n = static_cast<int>(camera.d.total());
  if (n != 4 && n != 5 && n != 0) {
    throw std::invalid_argument(
        fmt::format("StereoRectifier: {} distortion needs 4 or 5 values (k1 k2 p1 p2 [k3])", name));
  }
}

cv::Mat AsDouble(const cv::Mat& m) {
  cv::Mat out;
  m.convertTo(out, CV_64F);
  return out;
}

Eigen::Matrix<double, 3, 4> ToEigen3x4(const cv::Mat& p) {
  Eigen::Matrix<double, 3, 4> m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = p.at<double>(r, c);
  }
  return m;
}

cv::Point2d RectifyPixel(const cv::Point2d& raw, const RawCamera& camera, const cv::Mat& r,
                         const cv::Mat& p) {
  std::vector<cv::Point2d> in{raw}, out;
  cv::undistortPoints(in, out, camera.k, camera.d, r, p);
  return out.front();
}

}  // namespace

void StereoRectifier::Init(const RawCamera& left, const cv::Mat& left_r, const cv::Mat& left_p,
                           const RawCamera& right, const cv::Mat& right_r, const cv::Mat& right_p,
                           cv::Size size) {
  RequireCamera(left, "left K");
  RequireCamera(right, "right K");
  RequireShape(left_r, 3, 3, "left R");
  RequireShape(right_r, 3, 3, "right R");
  RequireShape(left_p, 3, 4, "left P");
  RequireShape(right_p, 3, 4, "right P");
  if (size.width <= 0 || size.height <= 0) {
    throw std::invalid_argument("StereoRectifier: the image size must be positive");
  }
  left_ = {AsDouble(left.k), AsDouble(left.d)};
  right_ = {AsDouble(right.k), AsDouble(right.d)};
  left_r_ = AsDouble(left_r);
  right_r_ = AsDouble(right_r);
  left_p_ = AsDouble(left_p);
  right_p_ = AsDouble(right_p);
  size_ = size;
  camera_ = StereoCamera::FromProjections(ToEigen3x4(left_p_), ToEigen3x4(right_p_), size.width,
                                          size.height);
  const cv::Mat left_k_new = left_p_(cv::Rect(0, 0, 3, 3));
  const cv::Mat right_k_new = right_p_(cv::Rect(0, 0, 3, 3));
  cv::initUndistortRectifyMap(left_.k, left_.d, left_r_, left_k_new, size, CV_16SC2, left_map1_,
                              left_map2_);
  cv::initUndistortRectifyMap(right_.k, right_.d, right_r_, right_k_new, size, CV_16SC2,
                              right_map1_, right_map2_);
}

StereoRectifier StereoRectifier::FromRectification(const RawCamera& left, const cv::Mat& left_r,
                                                   const cv::Mat& left_p, const RawCamera& right,
                                                   const cv::Mat& right_r, const cv::Mat& right_p,
                                                   cv::Size size) {
  StereoRectifier rectifier;
  rectifier.Init(left, left_r, left_p, right, right_r, right_p, size);
  return rectifier;
}

StereoRectifier StereoRectifier::FromExtrinsics(const RawCamera& left, const RawCamera& right,
                                                const cv::Mat& left_from_right, cv::Size size) {
  RequireCamera(left, "left K");
  RequireCamera(right, "right K");
  RequireShape(left_from_right, 4, 4, "left_from_right");
  const cv::Mat t = AsDouble(left_from_right);
  // cv::stereoRectify wants the second camera's pose in the first's: x_right = R x_left + T.
  const cv::Mat right_from_left_r = t(cv::Rect(0, 0, 3, 3)).t();
  const cv::Mat right_from_left_t = -right_from_left_r * t(cv::Rect(3, 0, 1, 3));
  cv::Mat r1, r2, p1, p2, q;
  cv::stereoRectify(AsDouble(left.k), AsDouble(left.d), AsDouble(right.k), AsDouble(right.d), size,
                    right_from_left_r, right_from_left_t, r1, r2, p1, p2, q,
                    cv::CALIB_ZERO_DISPARITY, 0.0, size);
  StereoRectifier rectifier;
  rectifier.Init(left, r1, p1, right, r2, p2, size);
  return rectifier;
}

StereoPair StereoRectifier::Rectify(const StereoPair& raw) const {
  if (raw.left.size() != size_ || raw.right.size() != size_) {
    throw std::invalid_argument(fmt::format(
        "StereoRectifier: images are {}x{} / {}x{}, the calibration is for {}x{}", raw.left.cols,
        raw.left.rows, raw.right.cols, raw.right.rows, size_.width, size_.height));
  }
  StereoPair out;
  cv::remap(raw.left, out.left, left_map1_, left_map2_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  cv::remap(raw.right, out.right, right_map1_, right_map2_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return out;
}

cv::Point2d StereoRectifier::RectifyLeftPixel(const cv::Point2d& raw) const {
  return RectifyPixel(raw, left_, left_r_, left_p_);
}

cv::Point2d StereoRectifier::RectifyRightPixel(const cv::Point2d& raw) const {
  return RectifyPixel(raw, right_, right_r_, right_p_);
}

}  // namespace planeloc
