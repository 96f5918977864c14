#include "planeloc/prior/plane_association.h"

#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "planeloc/prior/trajectory_consensus.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// Planes whose normals lie within 20 degrees are parallel for the bias statistics' bands: a
// pavement and the road, two layers of one facade.
const double kParallelCosine = std::cos(20.0 * std::numbers::pi / 180.0);

// A plane's window records are compared with the other planes' only from this many points on
// (fewer give no median worth comparing).
constexpr int kWindowPoints = 10;
// Metres: the trajectory's offset along a direction that no other plane holds, as a prior.
constexpr double kUnheldSigma = 1.0;

constexpr std::int64_t kAxisCells = 1 << 20;  // per axis, centred on 0: +-5 000 km at 5 m

ConsensusRule ConsensusRuleOf(const PlaneAssociationOptions& options) {
  ConsensusRule rule;
  rule.min_planes = options.consensus_min_planes;
  rule.min_points = options.consensus_min_points;
  rule.min_offset = options.consensus_min_offset;
  rule.tolerance = options.consensus_tolerance;
  rule.peer_angle_deg = options.bias_peer_angle_deg;
  return rule;
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
    : options_(options),
      map_name_(planes.source.empty() ? std::string("plane map") : planes.source.string()) {
  options_.Check();
  const double inflate =
      options_.polygon_margin + std::max(options_.max_distance, options_.stats_band);
  for (const MapPlane& plane : planes.planes) {
    if (plane.area > 0.0 && plane.area < options_.min_plane_area) continue;
    FlatPlane flat;
    flat.plane = plane;
    std::tie(flat.u, flat.v) = plane.plane_in_map.InPlaneBasis();
    const Eigen::Vector3d& up = planes.frame.up;
    flat.facade =
        plane.kind == "facade" || (plane.kind.empty() && !up.isZero() &&
                                   std::abs(plane.plane_in_map.normal.dot(up.normalized())) <
                                       std::sin(15.0 * std::numbers::pi / 180.0));
    const std::size_t index = planes_.size();
    index_by_id_[plane.id] = index;
    if (plane.polygon.size() < 3) {
      unbounded_.push_back(index);
      planes_.push_back(std::move(flat));
      continue;
    }
    Eigen::Vector3d lo = plane.polygon.front(), hi = plane.polygon.front();
    std::vector<Eigen::Vector2d> ring;
    for (const auto& p : plane.polygon) {
      ring.emplace_back(p.dot(flat.u), p.dot(flat.v));
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    flat.outline = IndexedPolygon2d(std::move(ring));
    lo.array() -= inflate;
    hi.array() += inflate;
    const Eigen::Array3d first = (lo / options_.cell_size).array().floor();
    const Eigen::Array3d last = (hi / options_.cell_size).array().floor();
    for (double x = first.x(); x <= last.x(); ++x) {
      for (double y = first.y(); y <= last.y(); ++y) {
        for (double z = first.z(); z <= last.z(); ++z) {
          cells_[CellKey(Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5) * options_.cell_size)]
              .push_back(index);
        }
      }
    }
    planes_.push_back(std::move(flat));
  }
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

std::int64_t PlaneAssociator::CellKey(const Eigen::Vector3d& point) const {
  const Eigen::Array3d c = (point / options_.cell_size).array().floor();
  auto axis = [](double value) {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>(value) + kAxisCells / 2, 0,
                                    kAxisCells - 1);
  };
  return (axis(c.x()) * kAxisCells + axis(c.y())) * kAxisCells + axis(c.z());
}

bool PlaneAssociator::InsideOutline(const FlatPlane& flat, const Eigen::Vector3d& point) const {
  if (flat.outline.ring().size() < 3) return true;
  const Eigen::Vector2d q(point.dot(flat.u), point.dot(flat.v));
  return flat.outline.InsideOrNear(q, options_.polygon_margin);
}

template <typename F>
void PlaneAssociator::ForCandidates(const Eigen::Vector3d& point_in_map, F f) const {
  for (const std::size_t index : unbounded_) {
    if (!f(index)) return;
  }
  const auto cell = cells_.find(CellKey(point_in_map));
  if (cell == cells_.end()) return;
  for (const std::size_t index : cell->second) {
    if (!f(index)) return;
  }
}

std::optional<int> PlaneAssociator::Associate(const Eigen::Vector3d& point_in_map) const {
  if (!point_in_map.allFinite()) return std::nullopt;
  std::optional<int> found;
  bool ambiguous = false;
  ForCandidates(point_in_map, [&](std::size_t index) {
    const FlatPlane& flat = planes_[index];
    if (std::abs(flat.plane.plane_in_map.SignedDistance(point_in_map)) > options_.max_distance) {
      return true;
    }
    if (!InsideOutline(flat, point_in_map)) return true;
    if (found && *found != flat.plane.id) {
      ambiguous = true;  // two planes claim the point
      return false;
    }
    found = flat.plane.id;
    return true;
  });
  if (ambiguous) return std::nullopt;
  return found;
}

double PlaneAssociator::Variance(const FlatPlane& flat) const {
  return flat.plane.rms * flat.plane.rms + options_.map_sigma * options_.map_sigma + flat.bias2;
}

std::optional<PlaneAssociation> PlaneAssociator::Associate(const PointEstimate& estimate) const {
  const Eigen::Vector3d& x = estimate.point_in_map;
  if (!x.allFinite() || !estimate.covariance.allFinite()) return std::nullopt;
  std::optional<PlaneAssociation> found;
  bool ambiguous = false;
  ForCandidates(x, [&](std::size_t index) {
    const FlatPlane& flat = planes_[index];
    const Plane& plane = flat.plane.plane_in_map;
    if (flat.health.disabled) return true;
    const double s = plane.SignedDistance(x);
    if (std::abs(s) > options_.max_distance) return true;
    const double map_variance = Variance(flat);
    const double variance = plane.normal.dot(estimate.covariance * plane.normal) + map_variance;
    if (s * s > options_.gate_chi2 * variance) return true;
    if (!InsideOutline(flat, x)) return true;
    if (found && found->plane_id != flat.plane.id) {
      ambiguous = true;
      return false;
    }
    found = PlaneAssociation{flat.plane.id, s, std::sqrt(variance), map_variance};
    return true;
  });
  if (ambiguous) return std::nullopt;
  return found;
}

void PlaneAssociator::ForgetPoint(int point_id) {
  for (FlatPlane& flat : planes_) {
    if (flat.distance_by_point.erase(point_id) > 0) flat.touched = true;
  }
}

void PlaneAssociator::Record(int point_id, const PointEstimate& estimate, int keyframe_id) {
  const Eigen::Vector3d& x = estimate.point_in_map;
  if (!x.allFinite() || !estimate.covariance.allFinite()) return;
  const std::optional<IndexedWitness> found =
      Witnessed(x, options_.stats_band, /*disabled_too=*/false);
  if (!found) return;
  const Eigen::Vector3d& normal = planes_[found->index].plane.plane_in_map.normal;
  const double point_variance = normal.dot(estimate.covariance * normal);
  if (point_variance > options_.stats_max_point_sigma * options_.stats_max_point_sigma) return;
  pending_.push_back({found->index, point_id, found->distance, keyframe_id});
}

std::optional<PlaneAssociator::Witness> PlaneAssociator::WitnessedPlane(
    const Eigen::Vector3d& point_in_map, double band, bool disabled_too) const {
  if (!point_in_map.allFinite()) return std::nullopt;
  const std::optional<IndexedWitness> found = Witnessed(point_in_map, band, disabled_too);
  if (!found) return std::nullopt;
  return Witness{planes_[found->index].plane.id, found->distance};
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
  ForCandidates(x, [&](std::size_t index) {
    const FlatPlane& flat = planes_[index];
    const double s = flat.plane.plane_in_map.SignedDistance(x);
    if (std::abs(s) > 3 * band || !InsideOutline(flat, x)) return true;
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
    if (std::abs(a.distance) > band || (planes_[a.index].health.disabled && !disabled_too)) {
      continue;
    }
    const Eigen::Vector3d& na = planes_[a.index].plane.plane_in_map.normal;
    double clear = band;
    for (const IndexedWitness& b : near) {
      if (b.index == a.index) continue;
      const double cosine = na.dot(planes_[b.index].plane.plane_in_map.normal);
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

bool PlaneAssociator::ExplainedByTrajectory(std::size_t index) const {
  std::set<int> keyframes;
  std::vector<double> own;
  for (const PendingRecord& record : window_records_) {
    if (record.index != index || record.keyframe_id < 0) continue;
    keyframes.insert(record.keyframe_id);
    own.push_back(record.distance);
  }
  // Too few of its points in this window to compare: judged on its statistics alone.
  if (static_cast<int>(own.size()) < kWindowPoints) return false;
  std::map<std::size_t, std::vector<double>> others;
  for (const PendingRecord& record : window_records_) {
    if (record.index == index || planes_[record.index].health.disabled) continue;
    if (keyframes.count(record.keyframe_id)) others[record.index].push_back(record.distance);
  }
  // The trajectory's offset e at those keyframes, least squares over the other planes' window
  // medians (each n_q.e = median_q, with the median's error, the plane's fit rms and its bias so
  // far; not Planes.mapSigma, the map's registration error, which moves all planes together and
  // is part of e), with a prior of kUnheldSigma that keeps a direction no plane holds unknown
  // rather than zero.
  Eigen::Matrix3d information = Eigen::Matrix3d::Identity() / (kUnheldSigma * kUnheldSigma);
  Eigen::Vector3d weighted = Eigen::Vector3d::Zero();
  for (auto& [other, distances] : others) {
    if (static_cast<int>(distances.size()) < kWindowPoints) continue;
    const RobustLocation location = RobustMedian(distances);
    const FlatPlane& flat = planes_[other];
    const Eigen::Vector3d& normal = flat.plane.plane_in_map.normal;
    const double weight = 1.0 / (location.standard_error * location.standard_error +
                                 flat.plane.rms * flat.plane.rms + flat.bias2);
    information += weight * normal * normal.transpose();
    weighted += weight * location.median * normal;
  }
  const Eigen::LDLT<Eigen::Matrix3d> solver(information);
  const Eigen::Vector3d offset = solver.solve(weighted);
  const Eigen::Vector3d& normal = planes_[index].plane.plane_in_map.normal;
  const double offset_variance = normal.dot(solver.solve(normal));
  const RobustLocation location = RobustMedian(own);
  const double sigma =
      std::sqrt(location.standard_error * location.standard_error + std::max(0.0, offset_variance));
  spdlog::debug(
      "plane health: window {} plane {}: {} points in the window at {:+.3f} m, the other planes "
      "seen from the same {} keyframes put the trajectory at {:+.3f} +- {:.3f} m along its normal",
      windows_, planes_[index].plane.id, own.size(), location.median, keyframes.size(),
      normal.dot(offset), std::sqrt(std::max(0.0, offset_variance)));
  return std::abs(location.median - normal.dot(offset)) <= options_.bias_significance * sigma;
}

TrajectoryConsensus PlaneAssociator::ConsensusOffset() const {
  if (!options_.trajectory_consensus) return {};
  // The window's facades with their points' distances (horizontal planes are no witnesses).
  std::map<std::size_t, ConsensusWitness> by_plane;
  for (const PendingRecord& record : pending_) {
    if (!planes_[record.index].facade) continue;
    ConsensusWitness& witness = by_plane[record.index];
    witness.plane_index = record.index;
    witness.normal = planes_[record.index].plane.plane_in_map.normal;
    witness.distances.push_back(record.distance);
  }
  std::vector<ConsensusWitness> witnesses;
  for (auto& [index, witness] : by_plane) witnesses.push_back(std::move(witness));
  return FindTrajectoryConsensus(std::move(witnesses), ConsensusRuleOf(options_));
}

TrajectoryConsensus PlaneAssociator::AccumulatedConsensus(
    const std::vector<std::size_t>& indices) const {
  if (!options_.trajectory_consensus) return {};
  std::vector<ConsensusWitness> witnesses;
  for (const std::size_t index : indices) {
    const FlatPlane& flat = planes_[index];
    if (!flat.facade || flat.health.disabled) continue;
    ConsensusWitness witness;
    witness.plane_index = index;
    witness.normal = flat.plane.plane_in_map.normal;
    for (const auto& [id, distance] : flat.distance_by_point) witness.distances.push_back(distance);
    witnesses.push_back(std::move(witness));
  }
  // Sparing a plane asks less than moving the map: two facades, still more than agree with the
  // trajectory as it is (a lone plane may be the wrong one).
  ConsensusRule rule = ConsensusRuleOf(options_);
  rule.min_planes = 2;
  return FindTrajectoryConsensus(std::move(witnesses), rule);
}

void PlaneAssociator::FinishRecords() {
  CloseRecords();
  CommitRecords();
}

void PlaneAssociator::CloseRecords() {
  consensus_ = ConsensusOffset();
  if (!consensus_.offset.isZero()) {
    std::string ids;
    for (const std::size_t index : consensus_.supporters) {
      ids += (ids.empty() ? "" : ", ") + std::to_string(planes_[index].plane.id);
    }
    spdlog::debug(
        "plane consensus: window {} trajectory offset [{:+.3f}, {:+.3f}, {:+.3f}] m from planes "
        "{}",
        windows_ + 1, consensus_.offset.x(), consensus_.offset.y(), consensus_.offset.z(), ids);
  }
}

void PlaneAssociator::CommitRecords() {
  for (const PendingRecord& record : pending_) {
    FlatPlane& flat = planes_[record.index];
    flat.distance_by_point[record.point_id] = record.distance;
    flat.touched = true;
  }
  window_records_.insert(window_records_.end(), pending_.begin(), pending_.end());
  pending_.clear();
}

int PlaneAssociator::UpdateHealth(int associations) {
  if (!pending_.empty()) FinishRecords();
  ++windows_;
  total_associations_ += associations;
  int disabled_now = 0, judged = 0;
  std::vector<double> values;
  std::vector<std::size_t> touched;  // planes with points in this window, statistics updated
  for (std::size_t index = 0; index < planes_.size(); ++index) {
    FlatPlane& flat = planes_[index];
    if (flat.health.points >= options_.bias_min_points) ++judged;
    if (!flat.touched || flat.health.disabled) continue;
    flat.touched = false;
    touched.push_back(index);
    values.clear();
    for (const auto& [id, s] : flat.distance_by_point) values.push_back(s);
    const std::size_t n = values.size();
    const RobustLocation location = RobustMedian(values);
    PlaneHealth& health = flat.health;
    const bool was_judged = health.points >= options_.bias_min_points;
    health.points = static_cast<int>(n);
    health.median = location.median;
    health.standard_error = location.standard_error;
    if (!was_judged && health.points >= options_.bias_min_points) ++judged;
  }
  // Before a plane is blamed for its bias, its peers are asked: facades of about its normal that
  // show the same offset over all their points say the trajectory is off, not the plane. The
  // window's consensus alone sees too few points to protect them in time.
  const TrajectoryConsensus accumulated = AccumulatedConsensus(touched);
  for (const std::size_t index : touched) {
    FlatPlane& flat = planes_[index];
    PlaneHealth& health = flat.health;
    const Eigen::Vector3d& normal = flat.plane.plane_in_map.normal;
    // The trajectory's own error e in the map frame moves every plane's points by n.e: the
    // plane's bias is its points' median, with the trajectory's uncertainty along the normal.
    const double trajectory_sigma =
        std::sqrt(std::max(0.0, normal.dot(trajectory_covariance_ * normal)));
    const double bias = health.median;
    const double bias_sigma = std::hypot(health.standard_error, trajectory_sigma);
    // Down-weighting: from half the points needed to judge, the part of the bias the
    // trajectory's uncertainty does not explain joins the plane sigma.
    const double unexplained = std::max(0.0, std::abs(bias) - trajectory_sigma);
    flat.bias2 = 2 * health.points >= options_.bias_min_points ? unexplained * unexplained : 0.0;
    spdlog::debug(
        "plane health: window {} plane {} points {} median {:+.3f} m (se {:.3f}, trajectory "
        "{:.3f})",
        windows_, flat.plane.id, health.points, health.median, health.standard_error,
        trajectory_sigma);
    // The window's planes agree that the trajectory is off by this plane's offset: the
    // trajectory's error, not the plane's, until the tracker has corrected it or not.
    const auto supports = [index](const TrajectoryConsensus& consensus) {
      return std::find(consensus.supporters.begin(), consensus.supporters.end(), index) !=
             consensus.supporters.end();
    };
    const bool explained = supports(consensus_) || supports(accumulated);
    if (!explained && health.points >= options_.bias_min_points &&
        std::abs(bias) > options_.bias_min &&
        std::abs(bias) > options_.bias_significance * bias_sigma && !ExplainedByTrajectory(index)) {
      flat.bias2 = 0;
      flat.distance_by_point.clear();
      health.disabled = true;
      ++num_disabled_;
      ++disabled_now;
      spdlog::warn(
          "{}: plane {} disabled for this run: its {} points sit {:+.3f} m off it (median signed "
          "distance of their stereo estimates, standard error {:.3f} m with the trajectory's "
          "uncertainty); the map is wrong there",
          map_name_, flat.plane.id, health.points, health.median, bias_sigma);
    }
  }
  if (!warned_no_association_ && windows_ >= options_.warn_after_windows &&
      total_associations_ == 0 && !planes_.empty()) {
    warned_no_association_ = true;
    spdlog::warn(
        "{}: no map point passed the association gate of any plane in the first {} keyframes; "
        "the plane map is probably in another frame than the trajectory (check the initial pose "
        "and the map's frame) or of another place",
        map_name_, windows_);
  }
  if (!warned_most_disabled_ && judged >= 3 && 2 * num_disabled_ > judged) {
    warned_most_disabled_ = true;
    spdlog::warn(
        "{}: {} of the {} planes with enough points are disabled (their points sit off them): "
        "the plane map is probably wrong (another frame, a bad registration, an outdated map)",
        map_name_, num_disabled_, judged);
  }
  window_records_.clear();
  return disabled_now;
}

void PlaneAssociator::SetTrajectoryCovariance(const Eigen::Matrix3d& position_covariance_in_map) {
  if (!position_covariance_in_map.allFinite()) {
    throw std::invalid_argument("PlaneAssociator::SetTrajectoryCovariance: not finite");
  }
  trajectory_covariance_ = position_covariance_in_map;
}

void PlaneAssociator::ResetHealth() {
  for (FlatPlane& flat : planes_) {
    flat.health = PlaneHealth{};
    flat.bias2 = 0;
    flat.distance_by_point.clear();
    flat.touched = false;
  }
  num_disabled_ = 0;
  pending_.clear();
  window_records_.clear();
  consensus_ = TrajectoryConsensus{};
}

void PlaneAssociator::PlanesNear(const Eigen::Vector3d& point_in_map, std::vector<int>& ids) const {
  if (!point_in_map.allFinite()) return;
  ForCandidates(point_in_map, [&](std::size_t index) {
    ids.push_back(planes_[index].plane.id);
    return true;
  });
}

bool PlaneAssociator::InsideOutline(int id, const Eigen::Vector3d& point_in_map,
                                    double margin) const {
  const FlatPlane& flat = planes_[index_by_id_.at(id)];
  if (flat.outline.ring().size() < 3) return true;
  const Eigen::Vector2d q(point_in_map.dot(flat.u), point_in_map.dot(flat.v));
  return flat.outline.InsideOrNear(q, margin);
}

const MapPlane& PlaneAssociator::plane(int id) const {
  const auto it = index_by_id_.find(id);
  if (it == index_by_id_.end()) {
    throw std::out_of_range("PlaneAssociator: no plane with id " + std::to_string(id));
  }
  return planes_[it->second].plane;
}

const PlaneHealth& PlaneAssociator::health(int id) const {
  const auto it = index_by_id_.find(id);
  if (it == index_by_id_.end()) {
    throw std::out_of_range("PlaneAssociator: no plane with id " + std::to_string(id));
  }
  return planes_[it->second].health;
}

std::vector<int> PlaneAssociator::DisabledIds() const {
  std::vector<int> ids;
  for (const FlatPlane& flat : planes_) {
    if (flat.health.disabled) ids.push_back(flat.plane.id);
  }
  std::sort(ids.begin(), ids.end());
  return ids;
}

double PlaneAssociator::PlaneSigma(int id) const {
  const auto it = index_by_id_.find(id);
  if (it == index_by_id_.end()) {
    throw std::out_of_range("PlaneAssociator: no plane with id " + std::to_string(id));
  }
  return std::sqrt(Variance(planes_[it->second]));
}

}  // namespace planeloc
