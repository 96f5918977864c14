// Which visual map points lie on a plane of the LiDAR prior (planes.json): the association that
// gives a point its point-to-plane residual in the window BA (the paper's points p on a plane vs
// points q off planes).
//
// A point is tested with its visual-only estimate (PointEstimate: the stereo observations of
// the point, each back-projected from its keyframe, fused; the BA moves the keyframes but not
// these measurements, so a point is not kept on a plane only because the plane pulled it there).
// It is on plane k when
//   - its projection onto the plane lies inside the plane's outline grown by `polygon_margin`
//     (the outline is where the LiDAR saw the surface: the infinite extension of a facade runs
//     through the street behind it),
//   - its signed distance s passes the chi-square gate s^2 <= gate_chi2 * sigma^2 with
//     sigma^2 = n^T Sigma_point n + sigma_plane^2, sigma_plane^2 = rms^2 + map_sigma^2 + bias^2
//     (the plane's fitted rms from planes.json, the map's registration error, and the bias its
//     points showed so far, see below),
//   - and |s| <= max_distance (a hard outer cap whatever the uncertainty).
// A point that passes the gate of two planes (a crease, a kerb) is not associated: the wrong
// choice would pull it across the crease, and the BA loses little by leaving it visual only.
//
// A map can be wrong (registration errors, a city that changed). Every plane keeps the signed
// distances of the points around it (|s| <= stats_band, precise enough along its normal, latest
// value per point; near a parallel plane the band is symmetric and clear of the other's band,
// none where they are closer than stats_band, and a point within the band of a crossing plane
// witnesses neither, even where it is too imprecise to witness that one):
// when their median sits off the plane by more than bias_min and bias_significance standard
// errors, over at least bias_min_points points, the plane is disabled for the run (logged once),
// unless the other planes seen from the same keyframes in the current window put the trajectory
// there off by about the plane's offset, or leave its normal unheld (ExplainedByTrajectory);
// before that its bias already inflates its sigma (down-weighting).
// The planes' geometry and lookup grid are PlaneLookup's (plane_lookup.h), their statistics
// PlaneHealthMonitor's (plane_health.h); this class applies the gate and the witness rule.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/plane.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/prior/crease_check.h"
#include "planeloc/prior/plane_health.h"
#include "planeloc/prior/plane_lookup.h"
#include "planeloc/prior/trajectory_consensus.h"

namespace planeloc {

struct PlaneAssociationOptions {
  double max_distance = 0.15;   // metres: hard outer cap of the gate
  double polygon_margin = 0.5;  // metres outside the outline still accepted
  double min_plane_area = 8.0;  // m^2: smaller planes of the map are not used
  double cell_size = 5.0;       // metres, lookup grid
  // Chi-square gate (1 DoF) on the signed distance; 6.635 = 99 % (Planes.gateChi2).
  double gate_chi2 = 6.635;
  // Metres: registration error of the map, added (in quadrature) to each plane's fitted rms
  // (Planes.mapSigma).
  double map_sigma = 0.05;
  // Pixels: keypoint position noise at pyramid level 0 (times scale_factor^octave above); the
  // disparity has sqrt(2) times that (Planes.pixelSigma).
  double pixel_sigma = 0.4;
  // Staged activation: a window with fewer associated points is solved as plain visual BA
  // (Planes.minAssociations).
  int min_associations = 30;
  // Bias statistics (Planes.statsBand, Planes.statsMaxPointSigma): points within stats_band
  // metres of a plane (inside its outline) whose own sigma along the normal is at most
  // stats_max_point_sigma metres.
  double stats_band = 0.35;
  double stats_max_point_sigma = 0.15;
  // Metres: a smaller bias never disables a plane, it only down-weights it (Planes.biasMin).
  double bias_min = 0.1;
  double bias_significance = 4.0;  // |median| > this many standard errors (Planes.biasSignificance)
  int bias_min_points = 40;        // distinct points before a plane can be disabled
  // Degrees: planes whose normals lie within this face the same direction, for the trajectory
  // consensus (Planes.biasPeerAngleDeg).
  double bias_peer_angle_deg = 20.0;
  // The trajectory's offset from the map, estimated per window from the facades that agree on it
  // (trajectory_consensus.h; Planes.trajectoryConsensus, on by default): at least
  // consensus_min_planes facades of about the same normal, each with consensus_min_points points
  // in the window, agreeing within consensus_tolerance metres on an offset of at least
  // consensus_min_offset metres, and outnumbering those that agree with the trajectory as it is.
  // The window reports it (trajectory_offset()), its supporters are not disabled in that window,
  // and the tracker moves its map by it when two windows in a row agree (Tracker::MakeBaJob).
  // The same rule over the facades' accumulated points, with two facades enough, spares its
  // supporters from the bias test too (AccumulatedConsensus).
  bool trajectory_consensus = true;
  int consensus_min_planes = 3;
  int consensus_min_points = 3;
  double consensus_min_offset = 0.08;  // metres
  double consensus_tolerance = 0.05;   // metres
  // Windows after which "no map point passed the gate of any plane" is reported as a likely
  // wrong map.
  int warn_after_windows = 10;
  // The image-side check of the map at keyframes (crease_check.h; per-keyframe stats)
  // (Planes.creaseCheck, on by default).
  bool crease_check = true;
  // The crease check's options; its creases.min_plane_area is set from min_plane_area.
  CreaseCheckOptions crease;

  void Check() const;  // throws OptionsError naming the field
};

// A point position with its covariance (world = map frame), from stereo measurements only.
struct PointEstimate {
  Eigen::Vector3d point_in_map = Eigen::Vector3d::Zero();
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // m^2
};

// One stereo observation (left pixel (u, v), right column u_right > 0 disparity away) of a
// keyframe at `cam_from_world`, back-projected, with the covariance of (u, v, disparity)
// = diag(s^2, s^2, 2 s^2), s = pixel_sigma, propagated through x = (u - cx) b / disp,
// y = (v - cy) fx b / (fy disp), z = fx b / disp (so sigma_z = z^2 / (fx b) * sqrt(2) s) and
// rotated into the world. std::nullopt for a disparity <= 0.
std::optional<PointEstimate> StereoPointEstimate(const StereoCamera& camera,
                                                 const Rigid3d& cam_from_world, double u_left,
                                                 double v, double u_right, double pixel_sigma);
// Information-weighted fusion of independent estimates (at least one).
PointEstimate FusePointEstimates(const std::vector<PointEstimate>& estimates);

struct PlaneAssociation {
  int plane_id = 0;
  double signed_distance = 0;  // metres, of the estimate
  double sigma = 0;            // metres: the gate's sigma, also the BA residual's
  double map_variance = 0;     // m^2: the plane's part of sigma^2 (rms, map sigma, bias)
};

class PlaneAssociator {
 public:
  // Keeps the planes with at least min_plane_area (all of them when their area is unknown, 0).
  // Warnings name the map by planes.source (the planes.json path) when set.
  PlaneAssociator(const PlaneMap& planes, const PlaneAssociationOptions& options);

  // The plane `point_in_map` lies on (fixed band max_distance), if exactly one. No statistics.
  std::optional<int> Associate(const Eigen::Vector3d& point_in_map) const;
  // The plane the estimate lies on by the chi-square gate, if exactly one enabled plane.
  std::optional<PlaneAssociation> Associate(const PointEstimate& estimate) const;

  // Records the signed distance of point `point_id` from the enabled planes around it (for the
  // bias statistics; the latest value per point counts). Call for every window point, then
  // FinishRecords before the window's Associate calls. `keyframe_id`: the newest keyframe that
  // observes the point (-1: unknown); a plane is blamed for its offset only where the other
  // planes seen from the same keyframes say the trajectory there is not off by it.
  void Record(int point_id, const PointEstimate& estimate, int keyframe_id = -1);
  // Estimates the trajectory's offset from the pending records (options.trajectory_consensus;
  // zero otherwise or without a consensus). The records stay pending.
  void CloseRecords() { health_.CloseRecords(lookup_); }
  // Adds the pending records to the planes' statistics.
  void CommitRecords() { health_.CommitRecords(); }
  // Drops the pending records (the window they measured was moved before it was used).
  void DiscardRecords() { health_.DiscardRecords(); }
  // CloseRecords, then CommitRecords. UpdateHealth calls it when records are pending.
  void FinishRecords() { health_.FinishRecords(lookup_); }
  // The offset of the last CloseRecords (map frame, metres): the estimated trajectory error e,
  // points sit at n.e off a correct plane. Zero when no consensus.
  const Eigen::Vector3d& trajectory_offset() const { return health_.consensus().offset; }
  // Drops the point's recorded distance (a point merged into another by map-point fusion: the
  // survivor stands for both, and counting the duplicate would double its weight).
  void ForgetPoint(int point_id) { health_.ForgetPoint(point_id); }
  // Recomputes the statistics of the planes recorded since the last call, disables biased
  // ones (spdlog warn each) and warns once when the map looks wrong. `associations`: points
  // associated in the window just built. Returns the number of planes disabled by this call.
  int UpdateHealth(int associations) { return health_.UpdateHealth(lookup_, associations); }
  // How far the trajectory itself may be off in the map frame (position covariance, m^2, map
  // axes), e.g. right after a map lock: a plane's points then sit off it by n^T e for a camera
  // error e, so the bias test allows n^T C n on top of the median's standard error, and only the
  // part of the bias beyond sqrt(n^T C n) down-weights the plane. Zero (the default): the
  // trajectory is taken as right and every bias is the map's.
  void SetTrajectoryCovariance(const Eigen::Matrix3d& position_covariance_in_map) {
    health_.SetTrajectoryCovariance(position_covariance_in_map);
  }
  // Forgets every plane's statistics and re-enables the disabled ones: after a correction of the
  // map frame (a lock, a re-registration) the biases seen before it measured the trajectory's
  // error as much as the planes'. A plane that is really wrong is disabled again.
  void ResetHealth() { health_.Reset(); }

  // The image-side check at keyframe `keyframe_id` (options.crease_check; CreaseChecker::
  // CheckKeyframe) on level options.crease.lsd_level of its left ORB pyramid. std::nullopt when
  // the check is off or the pyramid has no such level.
  std::optional<CreaseCheckStats> CheckKeyframe(int keyframe_id, const Rigid3d& cam_from_world,
                                                const StereoCamera& camera,
                                                const std::vector<cv::Mat>& left_pyramid);
  const CreaseChecker* crease_checker() const { return creases_.get(); }

  // The plane that the point at `point_in_map` is a witness of, by the bias statistics' rule
  // (Record) with half-width `band`: within `band` of the plane and inside its outline, clear of
  // the bands of parallel neighbours (gap - band), and within `band` of no crossing plane (enabled
  // or disabled). Disabled planes are witnessed too when `disabled_too`. The point's precision is
  // the caller's test. Returns the plane's id and the point's signed distance from it.
  struct Witness {
    int plane_id = 0;
    double distance = 0;  // metres, signed
  };
  std::optional<Witness> WitnessedPlane(const Eigen::Vector3d& point_in_map, double band,
                                        bool disabled_too) const;
  // Appends to `ids` the planes (enabled or disabled) whose lookup cells contain the point: every
  // plane whose bounding box grown by polygon_margin + max(max_distance, stats_band) does.
  void PlanesNear(const Eigen::Vector3d& point_in_map, std::vector<int>& ids) const;
  // Whether the point's projection onto plane `id` lies inside its outline grown by `margin`
  // metres (always true for a plane without an outline).
  bool InsideOutline(int id, const Eigen::Vector3d& point_in_map, double margin) const;
  // Whether the map plane `id` is used (planes below min_plane_area are not).
  bool Contains(int id) const { return lookup_.IndexOf(id).has_value(); }

  // Plane by id (as in planes.json). Throws std::out_of_range for an unknown id.
  const MapPlane& plane(int id) const;
  const PlaneHealth& health(int id) const;
  // sqrt(rms^2 + map_sigma^2 + bias^2) of an enabled plane, metres.
  double PlaneSigma(int id) const;
  std::size_t size() const { return lookup_.size(); }
  int num_disabled() const { return health_.num_disabled(); }  // currently disabled
  std::vector<int> DisabledIds() const;  // ids of the disabled planes, ascending

 private:
  // The index in lookup_ of map plane `id`; throws std::out_of_range for an unknown id.
  std::size_t IndexOf(int id) const;
  // sigma_plane^2 of plane `index`: rms^2 + map_sigma^2 + bias^2.
  double Variance(std::size_t index) const;
  struct IndexedWitness {
    std::size_t index;
    double distance;
  };
  std::optional<IndexedWitness> Witnessed(const Eigen::Vector3d& point_in_map, double band,
                                          bool disabled_too) const;

  PlaneAssociationOptions options_;
  PlaneLookup lookup_;
  PlaneHealthMonitor health_;               // indexed as lookup_
  std::unique_ptr<CreaseChecker> creases_;  // with options.crease_check
};

}  // namespace planeloc
