#include "planeloc/sim/street.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include "planeloc/util/error.h"

namespace planeloc::sim {
namespace {

constexpr double kStep = 0.5;  // metres between polyline samples

double WrapAngle(double a) { return std::atan2(std::sin(a), std::cos(a)); }

}  // namespace

StreetPath::StreetPath(std::vector<Eigen::Vector2d> points, bool closed)
    : points_(std::move(points)), closed_(closed) {
  if (points_.size() < 2) throw std::invalid_argument("StreetPath needs >= 2 points");
  if (closed_ && (points_.front() - points_.back()).norm() > 1e-9)
    points_.push_back(points_.front());
  arc_.assign(points_.size(), 0.0);
  for (std::size_t i = 1; i < points_.size(); ++i) {
    arc_[i] = arc_[i - 1] + (points_[i] - points_[i - 1]).norm();
  }
}

StreetPath StreetPath::FromCorners(const std::vector<Eigen::Vector2d>& corners, bool closed,
                                   double radius) {
  const std::size_t n = corners.size();
  std::vector<Eigen::Vector2d> points;
  auto add_line = [&](const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    const int steps = std::max(1, static_cast<int>(std::ceil((b - a).norm() / kStep)));
    for (int k = 0; k < steps; ++k)
      points.push_back(a + (b - a) * (static_cast<double>(k) / steps));
  };
  // Fillet at corner i: tangent points at `radius * tan(turn / 2)` from the corner.
  std::vector<Eigen::Vector2d> entry(n), exit(n);
  std::vector<bool> rounded(n, false);
  for (std::size_t i = 0; i < n; ++i) {
    entry[i] = exit[i] = corners[i];
    if (!closed && (i == 0 || i + 1 == n)) continue;
    const Eigen::Vector2d in = (corners[i] - corners[(i + n - 1) % n]).normalized();
    const Eigen::Vector2d out = (corners[(i + 1) % n] - corners[i]).normalized();
    const double turn = std::atan2(in.x() * out.y() - in.y() * out.x(), in.dot(out));
    const double cut = radius * std::tan(std::abs(turn) / 2.0);
    entry[i] = corners[i] - in * cut;
    exit[i] = corners[i] + out * cut;
    rounded[i] = std::abs(turn) > 1e-6;
  }
  auto add_arc = [&](std::size_t i) {
    const Eigen::Vector2d in = (corners[i] - corners[(i + n - 1) % n]).normalized();
    const Eigen::Vector2d out = (corners[(i + 1) % n] - corners[i]).normalized();
    const double turn = std::atan2(in.x() * out.y() - in.y() * out.x(), in.dot(out));
    const Eigen::Vector2d left(-in.y(), in.x());
    const Eigen::Vector2d centre = entry[i] + left * (turn > 0 ? radius : -radius);
    const double a0 = std::atan2(entry[i].y() - centre.y(), entry[i].x() - centre.x());
    const int steps = std::max(2, static_cast<int>(std::ceil(radius * std::abs(turn) / kStep)));
    for (int k = 0; k < steps; ++k) {
      const double a = a0 + turn * static_cast<double>(k) / steps;
      points.push_back(centre + radius * Eigen::Vector2d(std::cos(a), std::sin(a)));
    }
  };
  const std::size_t legs = closed ? n : n - 1;
  for (std::size_t i = 0; i < legs; ++i) {
    if (rounded[i]) add_arc(i);
    add_line(exit[i], entry[(i + 1) % n]);
  }
  if (!closed) points.push_back(corners.back());
  return StreetPath(std::move(points), closed);
}

double StreetPath::Wrap(double s) const {
  const double total = length();
  if (closed_) {
    s = std::fmod(s, total);
    return s < 0 ? s + total : s;
  }
  return std::clamp(s, 0.0, total);
}

std::size_t StreetPath::Segment(double s, double* fraction) const {
  s = Wrap(s);
  auto it = std::upper_bound(arc_.begin(), arc_.end(), s);
  std::size_t i = static_cast<std::size_t>(std::max<std::ptrdiff_t>(1, it - arc_.begin())) - 1;
  i = std::min(i, arc_.size() - 2);
  const double len = arc_[i + 1] - arc_[i];
  *fraction = len > 0 ? std::clamp((s - arc_[i]) / len, 0.0, 1.0) : 0.0;
  return i;
}

Eigen::Vector2d StreetPath::Position(double s) const {
  double f = 0;
  const std::size_t i = Segment(s, &f);
  return points_[i] + f * (points_[i + 1] - points_[i]);
}

Eigen::Vector2d StreetPath::Tangent(double s) const {
  // Central difference over +-1 m smooths the polyline's kinks.
  const Eigen::Vector2d a = Position(closed_ ? s - 1.0 : std::max(s - 1.0, 0.0));
  const Eigen::Vector2d b = Position(closed_ ? s + 1.0 : std::min(s + 1.0, length()));
  const Eigen::Vector2d d = b - a;
  return d.norm() > 1e-9 ? Eigen::Vector2d(d.normalized()) : Eigen::Vector2d::UnitX();
}

double StreetPath::Heading(double s) const {
  const Eigen::Vector2d t = Tangent(s);
  return std::atan2(t.y(), t.x());
}

double StreetPath::Curvature(double s) const {
  const double h = 2.0;
  return WrapAngle(Heading(s + h) - Heading(s - h)) / (2.0 * h);
}

double StreetPath::Distance(const Eigen::Vector2d& p) const {
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i + 1 < points_.size(); ++i) {
    const Eigen::Vector2d a = points_[i], ab = points_[i + 1] - a;
    const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-12), 0.0, 1.0);
    best = std::min(best, (a + t * ab - p).squaredNorm());
  }
  return std::sqrt(best);
}

StreetPath StreetPath::Offset(double lateral) const {
  std::vector<Eigen::Vector2d> out;
  const std::size_t n = closed_ ? points_.size() - 1 : points_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector2d t = Tangent(arc_[i]);
    out.push_back(points_[i] + lateral * Eigen::Vector2d(-t.y(), t.x()));
  }
  return StreetPath(std::move(out), closed_);
}

void DriveOptions::Check() const {
  if (!(min_speed > 0 && cruise_speed >= min_speed)) throw OptionsError("DriveOptions: speeds");
  if (!(lateral_accel > 0 && accel > 0)) throw OptionsError("DriveOptions: accelerations");
  if (!(rate_hz > 0)) throw OptionsError("DriveOptions.rate_hz must be > 0");
}

Eigen::Matrix3d VehicleFromCamRotation() {
  Eigen::Matrix3d r;
  // Columns: camera x (right) = -y_vehicle, camera y (down) = -z_vehicle, camera z = x_vehicle.
  r << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  return r;
}

namespace {

// Speed (m/s) on a grid of arc lengths start + k * ds: the turn limit, smoothed by the
// acceleration limit backwards (braking before a turn) and forwards (speeding up after it).
std::vector<double> SpeedProfile(const StreetPath& lane, double start, double distance, double ds,
                                 const DriveOptions& o, double jitter_phase) {
  const std::size_t n = static_cast<std::size_t>(distance / ds) + 2;
  std::vector<double> v(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double s = start + static_cast<double>(k) * ds;
    const double curvature = std::abs(lane.Curvature(s));
    const double jitter = 1.0 + 0.04 * std::sin(2.0 * M_PI * s / 83.0 + jitter_phase);
    double limit = o.cruise_speed * jitter;
    if (curvature > 1e-6) limit = std::min(limit, std::sqrt(o.lateral_accel / curvature));
    v[k] = std::clamp(limit, o.min_speed, 12.0);
  }
  for (std::size_t k = n - 1; k-- > 0;)
    v[k] = std::min(v[k], std::sqrt(v[k + 1] * v[k + 1] + 2 * o.accel * ds));
  for (std::size_t k = 1; k < n; ++k)
    v[k] = std::min(v[k], std::sqrt(v[k - 1] * v[k - 1] + 2 * o.accel * ds));
  return v;
}

// Arc lengths of the frames (10 Hz) integrating the speed profile in 10 ms steps.
std::vector<double> FrameArcs(const std::vector<double>& v, double start, double ds, int frames,
                              double rate_hz) {
  std::vector<double> arcs;
  double s = start;
  const int substeps = 10;
  const double dt = 1.0 / (rate_hz * substeps);
  for (int f = 0; f < frames; ++f) {
    arcs.push_back(s);
    for (int k = 0; k < substeps; ++k) {
      const std::size_t i = std::min(v.size() - 1, static_cast<std::size_t>((s - start) / ds));
      s += v[i] * dt;
    }
  }
  return arcs;
}

}  // namespace

double CruiseSpeedFor(const StreetPath& lane, int frames, double distance, DriveOptions o) {
  double lo = o.min_speed, hi = 12.0;
  for (int it = 0; it < 30; ++it) {
    o.cruise_speed = 0.5 * (lo + hi);
    const auto v = SpeedProfile(lane, o.start_s, distance * 1.5 + 50.0, 0.5, o, 0.0);
    const auto arcs = FrameArcs(v, o.start_s, 0.5, frames, o.rate_hz);
    (arcs.back() - o.start_s < distance ? lo : hi) = o.cruise_speed;
  }
  return 0.5 * (lo + hi);
}

std::vector<Rigid3d> DriveAlong(const StreetPath& lane, int frames, const DriveOptions& o,
                                std::uint32_t seed) {
  o.Check();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> phase(0.0, 2.0 * M_PI);
  double phases[6];
  for (double& p : phases) p = phase(rng);
  const double ds = 0.25;
  // 200 m past the last frame: far beyond the braking distance (v^2 / 2a = 60 m), so the speeds
  // of the first N frames do not depend on N.
  const double distance = frames * 12.0 / o.rate_hz + 200.0;
  const auto v = SpeedProfile(lane, o.start_s, distance, ds, o, phases[0]);
  const auto arcs = FrameArcs(v, o.start_s, ds, frames, o.rate_hz);
  const Eigen::Matrix3d vehicle_from_cam = VehicleFromCamRotation();
  std::vector<Rigid3d> poses;
  for (int f = 0; f < frames; ++f) {
    const double s = arcs[static_cast<std::size_t>(f)], t = f / o.rate_hz;
    const std::size_t i = std::min(v.size() - 2, static_cast<std::size_t>((s - o.start_s) / ds));
    const double accel = (v[i + 1] * v[i + 1] - v[i] * v[i]) / (2.0 * ds);
    const double lateral = v[i] * v[i] * lane.Curvature(s);
    const double deg = M_PI / 180.0;
    // Body motion: suspension vibration plus pitch under braking and roll out of turns.
    const double pitch = 0.25 * deg * std::sin(2 * M_PI * 1.3 * t + phases[1]) +
                         0.12 * deg * std::sin(2 * M_PI * 3.1 * t + phases[2]) - 0.4 * deg * accel;
    const double roll = 0.2 * deg * std::sin(2 * M_PI * 0.9 * t + phases[3]) +
                        0.08 * deg * std::sin(2 * M_PI * 2.7 * t + phases[4]) - 0.3 * deg * lateral;
    const double bounce = 0.008 * std::sin(2 * M_PI * 1.7 * t + phases[5]);
    const Eigen::Matrix3d world_from_vehicle =
        (Eigen::AngleAxisd(lane.Heading(s), Eigen::Vector3d::UnitZ()) *
         Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
         Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
            .toRotationMatrix();
    const Eigen::Vector2d ground = lane.Position(s);
    const Eigen::Vector3d centre(ground.x(), ground.y(), o.camera_height + bounce);
    poses.emplace_back(Eigen::Matrix3d(world_from_vehicle * vehicle_from_cam), centre);
  }
  return poses;
}

}  // namespace planeloc::sim
