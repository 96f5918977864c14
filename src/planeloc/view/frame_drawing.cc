#include "planeloc/view/frame_drawing.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace planeloc::view {
namespace {

constexpr double kNearZ = 0.5;  // metres: outline parts closer than this are not drawn

cv::Point ToPixel(const StereoCamera& camera, const Eigen::Vector3d& p) {
  // Fixed point (4 fractional bits) keeps sub-pixel positions in cv::line.
  return {static_cast<int>(std::lround((camera.fx * p.x() / p.z() + camera.cx) * 16)),
          static_cast<int>(std::lround((camera.fy * p.y() / p.z() + camera.cy) * 16))};
}

}  // namespace

cv::Scalar PlaneColorBgr(int plane_id) {
  // Golden-angle hues: neighbouring ids get distinct colours.
  const double hue = std::fmod(plane_id * 137.508, 360.0);
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue / 2, 170, 255));
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return {static_cast<double>(c[0]), static_cast<double>(c[1]), static_cast<double>(c[2])};
}

cv::Mat DrawTrackedFrame(const TrackedFrameView& view, const StereoCamera& camera,
                         const Rigid3d& world_from_cam, const PlaneMap* map) {
  if (view.left.empty()) return {};
  cv::Mat image;
  if (view.left.channels() == 1) {
    cv::cvtColor(view.left, image, cv::COLOR_GRAY2BGR);
  } else {
    image = view.left.clone();
  }
  image.convertTo(image, CV_8UC3, 0.55);
  if (map) {
    const Rigid3d cam_from_world = world_from_cam.Inverse();
    for (const MapPlane& plane : map->planes) {
      if (plane.polygon.size() < 3) continue;
      const bool disabled =
          std::binary_search(view.disabled_planes.begin(), view.disabled_planes.end(), plane.id);
      const cv::Scalar color = disabled ? cv::Scalar(60, 60, 235) : PlaneColorBgr(plane.id);
      const std::size_t n = plane.polygon.size();
      for (std::size_t k = 0; k < n; ++k) {
        Eigen::Vector3d a = cam_from_world * plane.polygon[k];
        Eigen::Vector3d b = cam_from_world * plane.polygon[(k + 1) % n];
        if (a.z() < kNearZ && b.z() < kNearZ) continue;
        // Clip the edge at the near plane.
        if (a.z() < kNearZ) a = b + (a - b) * ((b.z() - kNearZ) / (b.z() - a.z()));
        if (b.z() < kNearZ) b = a + (b - a) * ((a.z() - kNearZ) / (a.z() - b.z()));
        cv::line(image, ToPixel(camera, a), ToPixel(camera, b), color, 2, cv::LINE_AA, 4);
      }
    }
  }
  for (std::size_t i = 0; i < view.tracked.size(); ++i) {
    const int plane = i < view.tracked_plane.size() ? view.tracked_plane[i] : -1;
    const cv::Scalar color = plane >= 0 ? PlaneColorBgr(plane) : cv::Scalar(235, 235, 235);
    const cv::Point center(static_cast<int>(std::lround(view.tracked[i].x * 16)),
                           static_cast<int>(std::lround(view.tracked[i].y * 16)));
    cv::circle(image, center, 3 * 16, color, plane >= 0 ? cv::FILLED : 1, cv::LINE_AA, 4);
  }
  return image;
}

}  // namespace planeloc::view
