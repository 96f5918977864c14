#include "planeloc/prior/plane_creases.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <tuple>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// A plane with its outline in its own 2-D coordinates.
struct OutlinedPlane {
  const MapPlane* plane = nullptr;
  Eigen::Vector3d u, v;
  std::vector<Eigen::Vector2d> ring;
  Eigen::Vector3d lo, hi;  // bounding box of the outline, map frame

  Eigen::Vector2d InPlane(const Eigen::Vector3d& x) const { return {x.dot(u), x.dot(v)}; }
};

// Fraction of `samples` whose probe at `offset` lies inside the plane's outline.
double InsideFraction(const OutlinedPlane& flat, const std::vector<Eigen::Vector3d>& samples,
                      const Eigen::Vector3d& offset) {
  int inside = 0;
  for (const Eigen::Vector3d& p : samples)
    inside += InsidePolygon2d(flat.ring, flat.InPlane(p + offset));
  return samples.empty() ? 0.0 : static_cast<double>(inside) / samples.size();
}

// The in-plane direction perpendicular to the crease towards the plane's surface (see header).
Eigen::Vector3d SideOf(const OutlinedPlane& flat, const Eigen::Vector3d& direction,
                       const std::vector<Eigen::Vector3d>& samples, double probe) {
  // Both sides need evidence: most probes on one side inside, few on the other.
  constexpr double kInside = 0.5, kOutside = 0.25;
  const Eigen::Vector3d w = direction.cross(flat.plane->plane_in_map.normal).normalized();
  const double plus = InsideFraction(flat, samples, probe * w);
  const double minus = InsideFraction(flat, samples, -probe * w);
  if (plus >= kInside && minus <= kOutside) return w;
  if (minus >= kInside && plus <= kOutside) return -w;
  return Eigen::Vector3d::Zero();
}

// The map's planes with an outline (and not too small), sorted by id.
std::vector<OutlinedPlane> OutlinePlanes(const PlaneMap& map, const PlaneCreaseOptions& options) {
  std::vector<OutlinedPlane> planes;
  for (const MapPlane& plane : map.planes) {
    if (plane.polygon.size() < 3) continue;
    if (plane.area > 0.0 && plane.area < options.min_plane_area) continue;
    OutlinedPlane flat;
    flat.plane = &plane;
    std::tie(flat.u, flat.v) = plane.plane_in_map.InPlaneBasis();
    flat.lo = flat.hi = plane.polygon.front();
    for (const Eigen::Vector3d& p : plane.polygon) {
      flat.ring.push_back(flat.InPlane(p));
      flat.lo = flat.lo.cwiseMin(p);
      flat.hi = flat.hi.cwiseMax(p);
    }
    planes.push_back(std::move(flat));
  }
  std::sort(planes.begin(), planes.end(), [](const OutlinedPlane& a, const OutlinedPlane& b) {
    return a.plane->id < b.plane->id;
  });
  return planes;
}

// The intersection line of two planes, through its point nearest to the middle of the two
// outlines' boxes.
struct CreaseLine {
  Eigen::Vector3d origin, direction;
};

CreaseLine IntersectionLine(const OutlinedPlane& a, const OutlinedPlane& b) {
  const Plane& pa = a.plane->plane_in_map;
  const Plane& pb = b.plane->plane_in_map;
  const Eigen::Vector3d direction = pa.normal.cross(pb.normal).normalized();
  // Solve n_a.x = -d_a, n_b.x = -d_b, direction.x = direction.centre.
  const Eigen::Vector3d centre = 0.25 * (a.lo + a.hi + b.lo + b.hi);
  Eigen::Matrix3d system;
  system.row(0) = pa.normal.transpose();
  system.row(1) = pb.normal.transpose();
  system.row(2) = direction.transpose();
  const Eigen::Vector3d origin =
      system.partialPivLu().solve(Eigen::Vector3d(-pa.d, -pb.d, direction.dot(centre)));
  return {origin, direction};
}

// Runs of samples along the line that lie in (or within the margin of) both outlines, gaps up to
// max_gap bridged. Empty when the outlines' stretches of the line overlap less than min_length.
std::vector<std::vector<Eigen::Vector3d>> SupportedRuns(const OutlinedPlane& a,
                                                        const OutlinedPlane& b,
                                                        const CreaseLine& line,
                                                        const PlaneCreaseOptions& options) {
  const double margin = options.support_margin;
  const Eigen::Vector3d& origin = line.origin;
  const Eigen::Vector3d& direction = line.direction;
  // Parameter range where both outlines can be: their vertices projected onto the line.
  double t_lo = -1e300, t_hi = 1e300;
  for (const OutlinedPlane* flat : {&a, &b}) {
    double lo = 1e300, hi = -1e300;
    for (const Eigen::Vector3d& p : flat->plane->polygon) {
      const double t = (p - origin).dot(direction);
      lo = std::min(lo, t);
      hi = std::max(hi, t);
    }
    t_lo = std::max(t_lo, lo - margin);
    t_hi = std::min(t_hi, hi + margin);
  }
  std::vector<std::vector<Eigen::Vector3d>> runs;
  if (!(t_hi - t_lo >= options.min_length)) return runs;
  const int steps = static_cast<int>(std::floor((t_hi - t_lo) / options.sample_step));
  double last_supported = -1e300;
  for (int k = 0; k <= steps; ++k) {
    const double t = t_lo + k * options.sample_step;
    const Eigen::Vector3d x = origin + t * direction;
    if (!InsideOrNearPolygon2d(a.ring, a.InPlane(x), margin) ||
        !InsideOrNearPolygon2d(b.ring, b.InPlane(x), margin)) {
      continue;
    }
    if (runs.empty() || t - last_supported > options.max_gap + 1e-9) runs.emplace_back();
    runs.back().push_back(x);
    last_supported = t;
  }
  return runs;
}

// The creases of two planes (none when their boxes are apart or they are near parallel).
void AddCreasesOfPair(const OutlinedPlane& a, const OutlinedPlane& b,
                      const PlaneCreaseOptions& options, double cos_min_angle,
                      std::vector<PlaneCrease>& creases) {
  const double margin = options.support_margin;
  if ((a.lo.array() - margin > b.hi.array() + margin).any() ||
      (b.lo.array() - margin > a.hi.array() + margin).any()) {
    return;
  }
  const double cos_angle = std::abs(a.plane->plane_in_map.normal.dot(b.plane->plane_in_map.normal));
  if (cos_angle > cos_min_angle) return;
  const CreaseLine line = IntersectionLine(a, b);
  for (const std::vector<Eigen::Vector3d>& run : SupportedRuns(a, b, line, options)) {
    if ((run.back() - run.front()).norm() < options.min_length) continue;
    PlaneCrease crease;
    crease.id = static_cast<int>(creases.size());
    crease.plane_a = a.plane->id;
    crease.plane_b = b.plane->id;
    crease.start = run.front();
    crease.end = run.back();
    crease.angle_deg = std::acos(std::min(1.0, cos_angle)) * 180.0 / std::numbers::pi;
    crease.into_a = SideOf(a, line.direction, run, options.side_probe);
    crease.into_b = SideOf(b, line.direction, run, options.side_probe);
    creases.push_back(crease);
  }
}

}  // namespace

void PlaneCreaseOptions::Check() const {
  if (!(min_angle_deg > 0.0 && min_angle_deg <= 90.0)) {
    throw OptionsError("PlaneCreaseOptions.min_angle_deg must be in (0, 90] (degrees)");
  }
  if (!(support_margin >= 0.0)) {
    throw OptionsError("PlaneCreaseOptions.support_margin must be >= 0 (m)");
  }
  if (!(min_length > 0.0)) throw OptionsError("PlaneCreaseOptions.min_length must be > 0 (m)");
  if (!(max_gap >= 0.0)) throw OptionsError("PlaneCreaseOptions.max_gap must be >= 0 (m)");
  if (!(sample_step > 0.0)) throw OptionsError("PlaneCreaseOptions.sample_step must be > 0 (m)");
  if (!(side_probe > 0.0)) throw OptionsError("PlaneCreaseOptions.side_probe must be > 0 (m)");
  if (!(min_plane_area >= 0.0)) {
    throw OptionsError("PlaneCreaseOptions.min_plane_area must be >= 0 (m^2)");
  }
}

std::vector<PlaneCrease> ComputePlaneCreases(const PlaneMap& map,
                                             const PlaneCreaseOptions& options) {
  options.Check();
  const std::vector<OutlinedPlane> planes = OutlinePlanes(map, options);
  const double cos_min_angle = std::cos(options.min_angle_deg * std::numbers::pi / 180.0);
  std::vector<PlaneCrease> creases;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    for (std::size_t j = i + 1; j < planes.size(); ++j) {
      AddCreasesOfPair(planes[i], planes[j], options, cos_min_angle, creases);
    }
  }
  return creases;
}

}  // namespace planeloc
