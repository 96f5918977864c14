#include "planeloc/prior/plane_health.h"

#include <spdlog/spdlog.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <set>
#include <stdexcept>
#include <utility>

namespace planeloc {
namespace {

// A plane's window records are compared with the other planes' only from this many points on
// (fewer give no median worth comparing).
constexpr int kWindowPoints = 10;
// Metres: the trajectory's offset along a direction that no other plane holds, as a prior.
constexpr double kUnheldSigma = 1.0;

}  // namespace

PlaneHealthMonitor::PlaneHealthMonitor(std::size_t num_planes, const BiasTestOptions& options,
                                       std::string map_name)
    : options_(options), map_name_(std::move(map_name)), planes_(num_planes) {}

void PlaneHealthMonitor::Add(std::size_t index, int point_id, double distance, int keyframe_id) {
  pending_.push_back({index, point_id, distance, keyframe_id});
}

void PlaneHealthMonitor::ForgetPoint(int point_id) {
  for (PlaneState& state : planes_) {
    if (state.distance_by_point.erase(point_id) > 0) state.touched = true;
  }
}

bool PlaneHealthMonitor::ExplainedByTrajectory(const PlaneLookup& lookup, std::size_t index) const {
  std::set<int> keyframes;
  std::vector<double> own;
  for (const Record& record : window_records_) {
    if (record.index != index || record.keyframe_id < 0) continue;
    keyframes.insert(record.keyframe_id);
    own.push_back(record.distance);
  }
  // Too few of its points in this window to compare: judged on its statistics alone.
  if (static_cast<int>(own.size()) < kWindowPoints) return false;
  std::map<std::size_t, std::vector<double>> others;
  for (const Record& record : window_records_) {
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
    const MapPlane& plane = lookup[other].plane;
    const Eigen::Vector3d& normal = plane.plane_in_map.normal;
    const double weight = 1.0 / (location.standard_error * location.standard_error +
                                 plane.rms * plane.rms + planes_[other].bias2);
    information += weight * normal * normal.transpose();
    weighted += weight * location.median * normal;
  }
  const Eigen::LDLT<Eigen::Matrix3d> solver(information);
  const Eigen::Vector3d offset = solver.solve(weighted);
  const Eigen::Vector3d& normal = lookup[index].plane.plane_in_map.normal;
  const double offset_variance = normal.dot(solver.solve(normal));
  const RobustLocation location = RobustMedian(own);
  const double sigma =
      std::sqrt(location.standard_error * location.standard_error + std::max(0.0, offset_variance));
  spdlog::debug(
      "plane health: window {} plane {}: {} points in the window at {:+.3f} m, the other planes "
      "seen from the same {} keyframes put the trajectory at {:+.3f} +- {:.3f} m along its normal",
      windows_, lookup[index].plane.id, own.size(), location.median, keyframes.size(),
      normal.dot(offset), std::sqrt(std::max(0.0, offset_variance)));
  return std::abs(location.median - normal.dot(offset)) <= options_.bias_significance * sigma;
}

TrajectoryConsensus PlaneHealthMonitor::ConsensusOffset(const PlaneLookup& lookup) const {
  if (!options_.trajectory_consensus) return {};
  // The window's facades with their points' distances (horizontal planes are no witnesses).
  std::map<std::size_t, ConsensusWitness> by_plane;
  for (const Record& record : pending_) {
    if (!lookup[record.index].facade) continue;
    ConsensusWitness& witness = by_plane[record.index];
    witness.plane_index = record.index;
    witness.normal = lookup[record.index].plane.plane_in_map.normal;
    witness.distances.push_back(record.distance);
  }
  std::vector<ConsensusWitness> witnesses;
  for (auto& [index, witness] : by_plane) witnesses.push_back(std::move(witness));
  return FindTrajectoryConsensus(std::move(witnesses), options_.consensus);
}

TrajectoryConsensus PlaneHealthMonitor::AccumulatedConsensus(
    const PlaneLookup& lookup, const std::vector<std::size_t>& indices) const {
  if (!options_.trajectory_consensus) return {};
  std::vector<ConsensusWitness> witnesses;
  for (const std::size_t index : indices) {
    const PlaneState& state = planes_[index];
    if (!lookup[index].facade || state.health.disabled) continue;
    ConsensusWitness witness;
    witness.plane_index = index;
    witness.normal = lookup[index].plane.plane_in_map.normal;
    for (const auto& [id, distance] : state.distance_by_point)
      witness.distances.push_back(distance);
    witnesses.push_back(std::move(witness));
  }
  // Sparing a plane asks less than moving the map: two facades, still more than agree with the
  // trajectory as it is (a lone plane may be the wrong one).
  ConsensusRule rule = options_.consensus;
  rule.min_planes = 2;
  return FindTrajectoryConsensus(std::move(witnesses), rule);
}

void PlaneHealthMonitor::CloseRecords(const PlaneLookup& lookup) {
  consensus_ = ConsensusOffset(lookup);
  if (!consensus_.offset.isZero()) {
    std::string ids;
    for (const std::size_t index : consensus_.supporters) {
      ids += (ids.empty() ? "" : ", ") + std::to_string(lookup[index].plane.id);
    }
    spdlog::debug(
        "plane consensus: window {} trajectory offset [{:+.3f}, {:+.3f}, {:+.3f}] m from planes "
        "{}",
        windows_ + 1, consensus_.offset.x(), consensus_.offset.y(), consensus_.offset.z(), ids);
  }
}

void PlaneHealthMonitor::CommitRecords() {
  for (const Record& record : pending_) {
    PlaneState& state = planes_[record.index];
    state.distance_by_point[record.point_id] = record.distance;
    state.touched = true;
  }
  window_records_.insert(window_records_.end(), pending_.begin(), pending_.end());
  pending_.clear();
}

int PlaneHealthMonitor::UpdateHealth(const PlaneLookup& lookup, int associations) {
  if (!pending_.empty()) FinishRecords(lookup);
  ++windows_;
  total_associations_ += associations;
  int disabled_now = 0, judged = 0;
  std::vector<double> values;
  std::vector<std::size_t> touched;  // planes with points in this window, statistics updated
  for (std::size_t index = 0; index < planes_.size(); ++index) {
    PlaneState& state = planes_[index];
    if (state.health.points >= options_.bias_min_points) ++judged;
    if (!state.touched || state.health.disabled) continue;
    state.touched = false;
    values.clear();
    for (const auto& [id, s] : state.distance_by_point) values.push_back(s);
    PlaneHealth& health = state.health;
    if (values.empty()) {
      // Every point recorded on the plane has since been fused into another or forgotten
      // (ForgetPoint): nothing is left to judge it by until new points arrive. (The median of no
      // values read past the end: a room run crashed here, docs/experiments.md, session 40.)
      health = PlaneHealth{};
      state.bias2 = 0;
      continue;
    }
    touched.push_back(index);
    const std::size_t n = values.size();
    const RobustLocation location = RobustMedian(values);
    const bool was_judged = health.points >= options_.bias_min_points;
    health.points = static_cast<int>(n);
    health.median = location.median;
    health.standard_error = location.standard_error;
    if (!was_judged && health.points >= options_.bias_min_points) ++judged;
  }
  // Before a plane is blamed for its bias, its peers are asked: facades of about its normal that
  // show the same offset over all their points say the trajectory is off, not the plane. The
  // window's consensus alone sees too few points to protect them in time.
  const TrajectoryConsensus accumulated = AccumulatedConsensus(lookup, touched);
  for (const std::size_t index : touched) {
    PlaneState& state = planes_[index];
    const MapPlane& plane = lookup[index].plane;
    PlaneHealth& health = state.health;
    const Eigen::Vector3d& normal = plane.plane_in_map.normal;
    // The trajectory's own error e in the map frame moves every plane's points by n.e: the
    // plane's bias is its points' median, with the trajectory's uncertainty along the normal.
    const double trajectory_sigma =
        std::sqrt(std::max(0.0, normal.dot(trajectory_covariance_ * normal)));
    const double bias = health.median;
    const double bias_sigma = std::hypot(health.standard_error, trajectory_sigma);
    // Down-weighting: from half the points needed to judge, the part of the bias the
    // trajectory's uncertainty does not explain joins the plane sigma.
    const double unexplained = std::max(0.0, std::abs(bias) - trajectory_sigma);
    state.bias2 = 2 * health.points >= options_.bias_min_points ? unexplained * unexplained : 0.0;
    spdlog::debug(
        "plane health: window {} plane {} points {} median {:+.3f} m (se {:.3f}, trajectory "
        "{:.3f})",
        windows_, plane.id, health.points, health.median, health.standard_error, trajectory_sigma);
    // The window's planes agree that the trajectory is off by this plane's offset: the
    // trajectory's error, not the plane's, until the tracker has corrected it or not.
    const auto supports = [index](const TrajectoryConsensus& consensus) {
      return std::find(consensus.supporters.begin(), consensus.supporters.end(), index) !=
             consensus.supporters.end();
    };
    const bool explained = supports(consensus_) || supports(accumulated);
    if (!explained && health.points >= options_.bias_min_points &&
        std::abs(bias) > options_.bias_min &&
        std::abs(bias) > options_.bias_significance * bias_sigma &&
        !ExplainedByTrajectory(lookup, index)) {
      state.bias2 = 0;
      state.distance_by_point.clear();
      health.disabled = true;
      ++num_disabled_;
      ++disabled_now;
      spdlog::warn(
          "{}: plane {} disabled for this run: its {} points sit {:+.3f} m off it (median signed "
          "distance of their stereo estimates, standard error {:.3f} m with the trajectory's "
          "uncertainty); the map is wrong there",
          map_name_, plane.id, health.points, health.median, bias_sigma);
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

void PlaneHealthMonitor::SetTrajectoryCovariance(
    const Eigen::Matrix3d& position_covariance_in_map) {
  if (!position_covariance_in_map.allFinite()) {
    throw std::invalid_argument("PlaneAssociator::SetTrajectoryCovariance: not finite");
  }
  trajectory_covariance_ = position_covariance_in_map;
}

void PlaneHealthMonitor::Reset() {
  for (PlaneState& state : planes_) state = PlaneState{};
  num_disabled_ = 0;
  pending_.clear();
  window_records_.clear();
  consensus_ = TrajectoryConsensus{};
}

}  // namespace planeloc
