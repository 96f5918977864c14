#include "planeloc/geometry/camera.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace planeloc {

StereoCamera StereoCamera::FromProjections(const Eigen::Matrix<double, 3, 4>& p_left,
                                           const Eigen::Matrix<double, 3, 4>& p_right, int width,
                                           int height) {
  StereoCamera camera;
  camera.fx = p_left(0, 0);
  camera.fy = p_left(1, 1);
  camera.cx = p_left(0, 2);
  camera.cy = p_left(1, 2);
  camera.width = width;
  camera.height = height;
  if (std::abs(p_left(0, 0) - p_right(0, 0)) > 1e-6 * std::abs(p_left(0, 0)) ||
      std::abs(p_left(0, 2) - p_right(0, 2)) > 1e-6 * std::abs(p_left(0, 0) + 1.0)) {
    throw std::invalid_argument("left and right projection matrices are not rectified together");
  }
  // P(0,3) = -fx * x_offset of each camera relative to the rectified reference frame.
  camera.baseline = (p_left(0, 3) - p_right(0, 3)) / camera.fx;
  camera.Check();
  return camera;
}

Eigen::Matrix3d StereoCamera::K() const {
  Eigen::Matrix3d k;
  k << fx, 0, cx, 0, fy, cy, 0, 0, 1;
  return k;
}

std::optional<Eigen::Vector2d> StereoCamera::Project(const Eigen::Vector3d& point_in_cam) const {
  if (point_in_cam.z() <= 0) return std::nullopt;
  const double inv_z = 1.0 / point_in_cam.z();
  return Eigen::Vector2d(fx * point_in_cam.x() * inv_z + cx, fy * point_in_cam.y() * inv_z + cy);
}

std::optional<Eigen::Vector3d> StereoCamera::ProjectStereo(
    const Eigen::Vector3d& point_in_cam) const {
  if (point_in_cam.z() <= 0) return std::nullopt;
  const double inv_z = 1.0 / point_in_cam.z();
  const double u_left = fx * point_in_cam.x() * inv_z + cx;
  return Eigen::Vector3d(u_left, fy * point_in_cam.y() * inv_z + cy,
                         u_left - BaselineTimesFx() * inv_z);
}

Eigen::Vector3d StereoCamera::Unproject(const Eigen::Vector2d& pixel, double depth) const {
  return Eigen::Vector3d((pixel.x() - cx) * depth / fx, (pixel.y() - cy) * depth / fy, depth);
}

bool StereoCamera::InImage(const Eigen::Vector2d& pixel, double border) const {
  return pixel.x() >= border && pixel.y() >= border && pixel.x() <= width - 1 - border &&
         pixel.y() <= height - 1 - border;
}

void StereoCamera::Check() const {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("stereo camera: " + what);
  };
  require(std::isfinite(fx) && fx > 0, "fx must be > 0, got " + std::to_string(fx));
  require(std::isfinite(fy) && fy > 0, "fy must be > 0, got " + std::to_string(fy));
  require(std::isfinite(cx) && std::isfinite(cy), "cx, cy must be finite");
  require(std::isfinite(baseline) && baseline > 0,
          "baseline must be > 0 m (right camera to the right of the left one), got " +
              std::to_string(baseline));
  require(width >= 0 && height >= 0, "image size must be non-negative");
}

}  // namespace planeloc
