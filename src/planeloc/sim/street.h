// Street centre lines and the vehicle's motion along them, in the ground plane (z = 0) of the
// simulator's world frame W (x, y horizontal, z up).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "planeloc/geometry/rigid3.h"

namespace planeloc::sim {

// A polyline sampled every ~0.5 m, open or closed, parameterized by arc length s (metres).
class StreetPath {
 public:
  StreetPath() = default;
  StreetPath(std::vector<Eigen::Vector2d> points, bool closed);
  // Straight legs between `corners` with circular fillets of `radius` metres at every corner
  // (and at the first/last one of a closed path).
  static StreetPath FromCorners(const std::vector<Eigen::Vector2d>& corners, bool closed,
                                double radius);

  double length() const { return arc_.empty() ? 0.0 : arc_.back(); }
  bool closed() const { return closed_; }
  const std::vector<Eigen::Vector2d>& points() const { return points_; }

  // s wraps around for a closed path and is clamped to [0, length] for an open one.
  Eigen::Vector2d Position(double s) const;
  Eigen::Vector2d Tangent(double s) const;  // unit
  double Heading(double s) const;           // radians, atan2 of the tangent
  double Curvature(double s) const;         // 1/m, positive turning left
  // Distance from `point` to the polyline.
  double Distance(const Eigen::Vector2d& point) const;
  // The parallel curve `lateral` metres to the left (negative: right).
  StreetPath Offset(double lateral) const;

 private:
  double Wrap(double s) const;
  std::size_t Segment(double s, double* fraction) const;

  std::vector<Eigen::Vector2d> points_;  // closed paths repeat the first point at the end
  std::vector<double> arc_;
  bool closed_ = false;
};

struct DriveOptions {
  double cruise_speed = 10.0;   // m/s on straights (5..12)
  double min_speed = 5.0;       // m/s, floor of the speed in turns
  double lateral_accel = 2.0;   // m/s^2, sets the turn speed sqrt(a / curvature)
  double accel = 1.2;           // m/s^2, speeding up and braking limit
  double camera_height = 1.65;  // metres above the road, KITTI's
  double start_s = 0.0;         // arc length of the first frame
  double rate_hz = 10.0;
  void Check() const;
};

// world_from_cam (KITTI camera axes) of `frames` frames driving along `lane`, with slowing into
// turns, speed jitter, and small pitch/roll/bounce vibration drawn from `seed`.
std::vector<Rigid3d> DriveAlong(const StreetPath& lane, int frames, const DriveOptions& options,
                                std::uint32_t seed);
// Cruise speed in [min_speed, 12] m/s for which `frames` frames cover `distance` metres.
double CruiseSpeedFor(const StreetPath& lane, int frames, double distance, DriveOptions options);

// The fixed rotation from KITTI camera axes (x right, y down, z forward) to vehicle axes
// (x forward, y left, z up).
Eigen::Matrix3d VehicleFromCamRotation();

}  // namespace planeloc::sim
