#include "planeloc/prior/plane_association.h"

#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "planeloc/prior/trajectory_consensus.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// Planes whose normals lie within 20 degrees are parallel for the bias statistics' bands: a
// pavement and the road, two layers of one facade.
const double kParallelCosine = std::cos(20.0 * std::numbers::pi / 180.0);

ConsensusRule ConsensusRuleOf(const PlaneAssociationOptions& options) {
  ConsensusRule rule;
  rule.min_planes = options.consensus_min_planes;
  rule.min_points = options.consensus_min_points;
  rule.min_offset = options.consensus_min_offset;
  rule.tolerance = options.consensus_tolerance;
  rule.peer_angle_deg = options.bias_peer_angle_deg;
  return rule;
}

BiasTestOptions BiasTestOptionsOf(const PlaneAssociationOptions& options) {
  BiasTestOptions test;
  test.bias_min = options.bias_min;
  test.bias_significance = options.bias_significance;
  test.bias_min_points = options.bias_min_points;
  test.trajectory_consensus = options.trajectory_consensus;
  test.consensus = ConsensusRuleOf(options);
  test.warn_after_windows = options.warn_after_windows;
  return test;
}

const PlaneAssociationOptions& CheckedOptions(const PlaneAssociationOptions& options) {
  options.Check();
  return options;
}

}  // namespace

void PlaneAssociationOptions::Check() const {
  if (!(max_distance > 0.0)) {
    throw OptionsError("PlaneAssociationOptions.max_distance must be > 0 (m)");
  }
  if (!(polygon_margin >= 0.0)) {
    throw OptionsError("PlaneAssociationOptions.polygon_margin must be >= 0 (m)");
  }
  if (!(min_plane_area >= 0.0)) {
    throw OptionsError("PlaneAssociationOptions.min_plane_area must be >= 0 (m^2)");
  }
  if (!(cell_size > 0.0)) throw OptionsError("PlaneAssociationOptions.cell_size must be > 0 (m)");
  if (!(gate_chi2 > 0.0)) throw OptionsError("PlaneAssociationOptions.gate_chi2 must be > 0");
  if (!(map_sigma >= 0.0)) {
    throw OptionsError("PlaneAssociationOptions.map_sigma must be >= 0 (m)");
  }
  if (!(std::isfinite(bias_peer_angle_deg) && bias_peer_angle_deg >= 0 &&
        bias_peer_angle_deg < 90)) {
    throw OptionsError("PlaneAssociationOptions.bias_peer_angle_deg must be in [0, 90) degrees");
  }
  if (!(pixel_sigma > 0.0)) {
    throw OptionsError("PlaneAssociationOptions.pixel_sigma must be > 0 (px)");
  }
  if (min_associations < 0) {
    throw OptionsError("PlaneAssociationOptions.min_associations must be >= 0");
  }
  if (!(stats_band > 0.0)) {
    throw OptionsError("PlaneAssociationOptions.stats_band must be > 0 (m)");
  }
  if (!(stats_max_point_sigma > 0.0)) {
    throw OptionsError("PlaneAssociationOptions.stats_max_point_sigma must be > 0 (m)");
  }
  if (!(bias_min >= 0.0)) throw OptionsError("PlaneAssociationOptions.bias_min must be >= 0 (m)");
  if (!(bias_significance > 0.0)) {
    throw OptionsError("PlaneAssociationOptions.bias_significance must be > 0");
  }
  if (bias_min_points < 1) {
    throw OptionsError("PlaneAssociationOptions.bias_min_points must be >= 1");
  }
  if (warn_after_windows < 1) {
    throw OptionsError("PlaneAssociationOptions.warn_after_windows must be >= 1");
  }
  if (consensus_min_planes < 2) {
    throw OptionsError(
        "PlaneAssociationOptions.consensus_min_planes must be >= 2 (one plane could be the wrong "
        "one)");
  }
  if (consensus_min_points < 1) {
    throw OptionsError("PlaneAssociationOptions.consensus_min_points must be >= 1");
  }
  if (!(std::isfinite(consensus_min_offset) && consensus_min_offset >= 0.0)) {
    throw OptionsError("PlaneAssociationOptions.consensus_min_offset must be >= 0 (m)");
  }
  if (!(std::isfinite(consensus_tolerance) && consensus_tolerance > 0.0)) {
    throw OptionsError("PlaneAssociationOptions.consensus_tolerance must be > 0 (m)");
  }
  crease.Check();
}

std::optional<PointEstimate> StereoPointEstimate(const StereoCamera& camera,
                                                 const Rigid3d& cam_from_world, double u_left,
                                                 double v, double u_right, double pixel_sigma) {
  const double disparity = u_left - u_right;
  if (!(disparity > 0.0) || u_right < 0.0) return std::nullopt;
  const double b = camera.baseline, fx = camera.fx, fy = camera.fy;
  const double du = u_left - camera.cx, dv = v - camera.cy;
  const Eigen::Vector3d in_cam(du * b / disparity, dv * fx * b / (fy * disparity),
                               fx * b / disparity);
  Eigen::Matrix3d jacobian;  // d(x, y, z) / d(u, v, disparity)
  const double d2 = disparity * disparity;
  jacobian << b / disparity, 0, -du * b / d2,                  //
      0, fx * b / (fy * disparity), -dv * fx * b / (fy * d2),  //
      0, 0, -fx * b / d2;
  const double s2 = pixel_sigma * pixel_sigma;
  const Eigen::Vector3d measurement_variance(s2, s2, 2.0 * s2);
  const Eigen::Matrix3d in_cam_covariance =
      jacobian * measurement_variance.asDiagonal() * jacobian.transpose();
  const Rigid3d world_from_cam = cam_from_world.Inverse();
  const Eigen::Matrix3d rotation = world_from_cam.rotation.toRotationMatrix();
  PointEstimate estimate;
  estimate.point_in_map = world_from_cam * in_cam;
  estimate.covariance = rotation * in_cam_covariance * rotation.transpose();
  return estimate;
}

PointEstimate FusePointEstimates(const std::vector<PointEstimate>& estimates) {
  if (estimates.empty()) throw std::invalid_argument("FusePointEstimates: no estimate");
  if (estimates.size() == 1) return estimates.front();
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  for (const PointEstimate& e : estimates) {
    const Eigen::Matrix3d inverse = e.covariance.inverse();
    information += inverse;
    weighted += inverse * e.point_in_map;
  }
  PointEstimate fused;
  fused.covariance = information.inverse();
  fused.point_in_map = fused.covariance * weighted;
  return fused;
}

PlaneAssociator::PlaneAssociator(const PlaneMap& planes, const PlaneAssociationOptions& options)
    : options_(CheckedOptions(options)),
      lookup_(planes, options_.min_plane_area, options_.cell_size,
              options_.polygon_margin + std::max(options_.max_distance, options_.stats_band)),
      health_(lookup_.size(), BiasTestOptionsOf(options_),
              planes.source.empty() ? std::string("plane map") : planes.source.string()) {
  if (options_.crease_check) {
    CreaseCheckOptions crease = options_.crease;
    crease.creases.min_plane_area = options_.min_plane_area;
    creases_ = std::make_unique<CreaseChecker>(planes, crease);
  }
}

std::optional<CreaseCheckStats> PlaneAssociator::CheckKeyframe(
    int keyframe_id, const Rigid3d& cam_from_world, const StereoCamera& camera,
    const std::vector<cv::Mat>& left_pyramid) {
  const int level = options_.crease.lsd_level;
  if (!creases_ || level >= static_cast<int>(left_pyramid.size()) || left_pyramid[level].empty()) {
    return std::nullopt;
  }
  return creases_->CheckKeyframe(keyframe_id, cam_from_world, camera, left_pyramid[level]);
}

std::optional<int> PlaneAssociator::Associate(const Eigen::Vector3d& point_in_map) const {
  if (!point_in_map.allFinite()) return std::nullopt;
  std::optional<int> found;
  bool ambiguous = false;
  lookup_.ForCandidates(point_in_map, [&](std::size_t index) {
    const MapPlane& plane = lookup_[index].plane;
    if (std::abs(plane.plane_in_map.SignedDistance(point_in_map)) > options_.max_distance) {
      return true;
    }
    if (!lookup_.InsideOutline(index, point_in_map, options_.polygon_margin)) return true;
    if (found && *found != plane.id) {
      ambiguous = true;  // two planes claim the point
      return false;
    }
    found = plane.id;
    return true;
  });
  if (ambiguous) return std::nullopt;
  return found;
}

double PlaneAssociator::Variance(std::size_t index) const {
  const MapPlane& plane = lookup_[index].plane;
  return plane.rms * plane.rms + options_.map_sigma * options_.map_sigma + health_.bias2(index);
}

std::optional<PlaneAssociation> PlaneAssociator::Associate(const PointEstimate& estimate) const {
  const Eigen::Vector3d& x = estimate.point_in_map;
  if (!x.allFinite() || !estimate.covariance.allFinite()) return std::nullopt;
  std::optional<PlaneAssociation> found;
  bool ambiguous = false;
  lookup_.ForCandidates(x, [&](std::size_t index) {
    const MapPlane& map_plane = lookup_[index].plane;
    const Plane& plane = map_plane.plane_in_map;
    if (health_.disabled(index)) return true;
    const double s = plane.SignedDistance(x);
    if (std::abs(s) > options_.max_distance) return true;
    const double map_variance = Variance(index);
    const double variance = plane.normal.dot(estimate.covariance * plane.normal) + map_variance;
    if (s * s > options_.gate_chi2 * variance) return true;
    if (!lookup_.InsideOutline(index, x, options_.polygon_margin)) return true;
    if (found && found->plane_id != map_plane.id) {
      ambiguous = true;
      return false;
    }
    found = PlaneAssociation{map_plane.id, s, std::sqrt(variance), map_variance};
    return true;
  });
  if (ambiguous) return std::nullopt;
  return found;
}

void PlaneAssociator::Record(int point_id, const PointEstimate& estimate, int keyframe_id) {
  const Eigen::Vector3d& x = estimate.point_in_map;
  if (!x.allFinite() || !estimate.covariance.allFinite()) return;
  const std::optional<IndexedWitness> found =
      Witnessed(x, options_.stats_band, /*disabled_too=*/false);
  if (!found) return;
  const Eigen::Vector3d& normal = lookup_[found->index].plane.plane_in_map.normal;
  const double point_variance = normal.dot(estimate.covariance * normal);
  if (point_variance > options_.stats_max_point_sigma * options_.stats_max_point_sigma) return;
  health_.Add(found->index, point_id, found->distance, keyframe_id);
}

std::optional<PlaneAssociator::Witness> PlaneAssociator::WitnessedPlane(
    const Eigen::Vector3d& point_in_map, double band, bool disabled_too) const {
  if (!point_in_map.allFinite()) return std::nullopt;
  const std::optional<IndexedWitness> found = Witnessed(point_in_map, band, disabled_too);
  if (!found) return std::nullopt;
  return Witness{lookup_[found->index].plane.id, found->distance};
}

std::optional<PlaneAssociator::IndexedWitness> PlaneAssociator::Witnessed(const Eigen::Vector3d& x,
                                                                          double band,
                                                                          bool disabled_too) const {
  // The planes over the point, out to where a parallel neighbour still narrows a band.
  std::vector<IndexedWitness> near;
  // Disabled planes too: the surface they stand for is still there, near them. (The lookup grid
  // holds every plane within polygon_margin + max(max_distance, stats_band) of the point, 0.85 m
  // by default; a parallel one missed further off would have left a band of at least
  // 0.85 m - band, 0.25 m for the map update's 0.6 m.)
  lookup_.ForCandidates(x, [&](std::size_t index) {
    const double s = lookup_[index].plane.plane_in_map.SignedDistance(x);
    if (std::abs(s) > 3 * band || !lookup_.InsideOutline(index, x, options_.polygon_margin)) {
      return true;
    }
    for (const IndexedWitness& n : near) {
      if (n.index == index) return true;
    }
    near.push_back({index, s});
    return true;
  });
  // A plane's witnesses must be able to show a bias of either sign, and belong to it whichever
  // plane is wrong. Near a parallel plane (a pavement 0.12 m above the road) the points between
  // them are within both bands: an exclusive rule left each plane only the points beyond the
  // other (clutter 0.25-0.35 m above the pavement, tree trunks and poles, its only witnesses), and
  // halfway bands give a moved road's points to the pavement. So the band there is symmetric and
  // stays clear of the neighbour's band: gap - band, none closer than `band`. A crossing plane
  // within the band (a facade's foot) makes the point ambiguous, also where it is too imprecise
  // along the crossing plane's normal to witness that plane.
  std::optional<IndexedWitness> found;
  for (const IndexedWitness& a : near) {
    if (std::abs(a.distance) > band || (health_.disabled(a.index) && !disabled_too)) {
      continue;
    }
    const Eigen::Vector3d& na = lookup_[a.index].plane.plane_in_map.normal;
    double clear = band;
    for (const IndexedWitness& b : near) {
      if (b.index == a.index) continue;
      const double cosine = na.dot(lookup_[b.index].plane.plane_in_map.normal);
      if (std::abs(cosine) >= kParallelCosine) {
        const double b_along_a = cosine > 0 ? b.distance : -b.distance;
        clear = std::min(clear, std::abs(a.distance - b_along_a) - band);
      } else if (std::abs(b.distance) <= band) {
        return std::nullopt;
      }
    }
    if (std::abs(a.distance) < clear) found = a;
  }
  return found;
}

std::size_t PlaneAssociator::IndexOf(int id) const {
  const std::optional<std::size_t> index = lookup_.IndexOf(id);
  if (!index) throw std::out_of_range("PlaneAssociator: no plane with id " + std::to_string(id));
  return *index;
}

void PlaneAssociator::PlanesNear(const Eigen::Vector3d& point_in_map, std::vector<int>& ids) const {
  if (!point_in_map.allFinite()) return;
  lookup_.ForCandidates(point_in_map, [&](std::size_t index) {
    ids.push_back(lookup_[index].plane.id);
    return true;
  });
}

bool PlaneAssociator::InsideOutline(int id, const Eigen::Vector3d& point_in_map,
                                    double margin) const {
  return lookup_.InsideOutline(IndexOf(id), point_in_map, margin);
}

const MapPlane& PlaneAssociator::plane(int id) const { return lookup_[IndexOf(id)].plane; }

const PlaneHealth& PlaneAssociator::health(int id) const { return health_.health(IndexOf(id)); }

std::vector<int> PlaneAssociator::DisabledIds() const {
  std::vector<int> ids;
  for (std::size_t index = 0; index < lookup_.size(); ++index) {
    if (health_.disabled(index)) ids.push_back(lookup_[index].plane.id);
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

double PlaneAssociator::PlaneSigma(int id) const { return std::sqrt(Variance(IndexOf(id))); }

}  // namespace planeloc
