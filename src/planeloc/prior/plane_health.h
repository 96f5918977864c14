// The bias statistics that tell a wrong plane of the prior map from a wrong trajectory
// (plane_association.h states the rule; docs/tracking.md, "Plane health", says why each part is
// there). Per plane of a PlaneLookup: the latest signed distance of each point that witnesses it,
// their median and its standard error, the down-weighting bias, and whether the plane is disabled
// for the run. PlaneAssociator decides which plane a point witnesses and feeds the distances in;
// this class judges them.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "planeloc/prior/plane_lookup.h"
#include "planeloc/prior/trajectory_consensus.h"

namespace planeloc {

// Per plane: statistics of its points' signed distances (the visual estimates).
struct PlaneHealth {
  int points = 0;             // distinct points recorded
  double median = 0;          // metres, signed
  double standard_error = 0;  // metres, of the median (robust, from the MAD)
  bool disabled = false;
};

// The part of PlaneAssociationOptions that judges a plane (same meanings and defaults there).
struct BiasTestOptions {
  double bias_min = 0.1;
  double bias_significance = 4.0;
  int bias_min_points = 40;
  bool trajectory_consensus = true;
  ConsensusRule consensus;
  int warn_after_windows = 10;
};

class PlaneHealthMonitor {
 public:
  // `num_planes`: the lookup's size (every call passes that lookup). Warnings name `map_name`.
  PlaneHealthMonitor(std::size_t num_planes, const BiasTestOptions& options, std::string map_name);

  // Point `point_id`, seen last from keyframe `keyframe_id` (-1: unknown), witnesses plane
  // `index` at signed distance `distance`. Pending until CommitRecords.
  void Add(std::size_t index, int point_id, double distance, int keyframe_id);
  // Estimates the trajectory's offset from the pending records (options.trajectory_consensus;
  // zero otherwise or without a consensus). The records stay pending.
  void CloseRecords(const PlaneLookup& lookup);
  // Adds the pending records to the planes' statistics.
  void CommitRecords();
  void DiscardRecords() { pending_.clear(); }
  void FinishRecords(const PlaneLookup& lookup) {
    CloseRecords(lookup);
    CommitRecords();
  }
  const TrajectoryConsensus& consensus() const { return consensus_; }
  void ForgetPoint(int point_id);
  // Recomputes the statistics of the planes recorded since the last call and disables biased
  // ones; PlaneAssociator::UpdateHealth.
  int UpdateHealth(const PlaneLookup& lookup, int associations);
  void SetTrajectoryCovariance(const Eigen::Matrix3d& position_covariance_in_map);
  // Forgets every plane's statistics and re-enables the disabled ones.
  void Reset();

  const PlaneHealth& health(std::size_t index) const { return planes_[index].health; }
  bool disabled(std::size_t index) const { return planes_[index].health.disabled; }
  // m^2: the squared bias beyond the trajectory's uncertainty, once enough points (else 0).
  double bias2(std::size_t index) const { return planes_[index].bias2; }
  int num_disabled() const { return num_disabled_; }

 private:
  struct PlaneState {
    PlaneHealth health;
    double bias2 = 0;                         // m^2, squared median once enough points
    std::map<int, double> distance_by_point;  // point id -> latest signed distance
    bool touched = false;
  };
  struct Record {
    std::size_t index;
    int point_id;
    double distance;
    int keyframe_id;
  };
  // The consensus of the facades' records in pending_ (offset zero when none).
  TrajectoryConsensus ConsensusOffset(const PlaneLookup& lookup) const;
  // The consensus of the enabled facades among `indices` over all their recorded points.
  TrajectoryConsensus AccumulatedConsensus(const PlaneLookup& lookup,
                                           const std::vector<std::size_t>& indices) const;
  // Whether the other planes' records of this window, from the keyframes that saw the plane's
  // own records, put the trajectory off along its normal by about the plane's offset, or leave
  // that direction unheld (then the plane cannot be told from the trajectory either).
  bool ExplainedByTrajectory(const PlaneLookup& lookup, std::size_t index) const;

  BiasTestOptions options_;
  std::string map_name_;
  std::vector<PlaneState> planes_;
  Eigen::Matrix3d trajectory_covariance_ = Eigen::Matrix3d::Zero();
  std::vector<Record> pending_;         // Add calls since the last CommitRecords
  std::vector<Record> window_records_;  // committed since the last UpdateHealth
  TrajectoryConsensus consensus_;       // of the last CloseRecords (supporters: indices in planes_)
  int num_disabled_ = 0;
  int windows_ = 0;
  long long total_associations_ = 0;
  bool warned_no_association_ = false, warned_most_disabled_ = false;
};

}  // namespace planeloc
