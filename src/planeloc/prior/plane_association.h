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
// distances of the points around it (|s| <= stats_band, precise enough, latest value per point):
// when their median sits off the plane by more than bias_min and bias_significance standard
// errors, over at least bias_min_points points, the plane is disabled for the run (logged once);
// before that its bias already inflates its sigma (down-weighting).
// Planes are found through a coarse 3-D grid of their inflated bounding boxes, so a query costs a
// few polygon tests whatever the size of the map.
#pragma once

#include <Eigen/Core>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/plane.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/prior/crease_check.h"
#include "planeloc/prior/trajectory_consensus.h"

namespace planeloc {

struct PlaneAssociationOptions {
  double max_distance = 0.15;   // metres: hard outer cap of the gate
  double polygon_margin = 0.5;  // metres outside the outline still accepted
  double min_plane_area = 8.0;  // m^2: smaller planes of the map are not used
  double cell_size = 5.0;       // metres, lookup grid
  // Chi-square gate (1 DoF) on the signed distance; 6.635 = 99 %.
  double gate_chi2 = 6.635;
  // Metres: registration error of the map, added (in quadrature) to each plane's fitted rms
  // (Planes.mapSigma). 0.05 = the former global LocalBA.planeSigma; 0.03 was measured worse.
  double map_sigma = 0.05;
  // Pixels: keypoint position noise at pyramid level 0 (times scale_factor^octave above); the
  // disparity has sqrt(2) times that (Planes.pixelSigma). 0.4: on the simulator's clean maps the
  // median |s| / sigma_n of the points was 0.26-0.32 at 1 px (0.674 when calibrated).
  double pixel_sigma = 0.4;
  // Staged activation: a window with fewer associated points is solved as plain visual BA
  // (Planes.minAssociations).
  int min_associations = 30;
  // The map's error of a plane (its rms, map_sigma, its bias) is the same for every point on it:
  // N points in a window do not average it down. With this > 0, a window with N_k points
  // associated with plane k weighs each of them with sigma^2 = n^T C n + map variance *
  // max(1, N_k / common_mode_points), so that the window draws from the plane's map error no
  // more information than this many independent points would give (Planes.commonModePoints;
  // 0: off, every point counts as independent).
  int common_mode_points = 0;
  // The plane's map error as a nuisance of each window (Planes.planeCorrection): the window BA
  // estimates a correction (offset, tilt) per associated plane with the prior sigmas
  // sqrt(map_sigma^2 + bias^2) and correction_tilt_sigma_deg (window_ba.h, WindowPlane), and a
  // point's residual carries only its own sigma (n^T C n + rms^2). The exact form of what
  // common_mode_points approximates (which it then replaces): N points on one plane tie the
  // window to the map once, and a tilted plane cannot rotate the keyframes beyond its prior.
  bool plane_correction = false;
  double correction_tilt_sigma_deg = 0.5;  // degrees; 0: offset only
  // A map that can be wrong (Planes.bias*): statistics over points within stats_band metres
  // (inside the outline) whose own sigma along the normal is at most stats_max_point_sigma.
  // Metres: 0.5 let points of other surfaces near small planes dominate the median (a clean
  // plane at +0.38 m on the tiny preset); 0.35 still sees planes moved by 0.3 m.
  double stats_band = 0.35;
  double stats_max_point_sigma = 0.15;  // metres
  // Metres: a smaller bias never disables a plane (it only down-weights it). Clean simulator
  // maps showed planes with biases of 0.06-0.14 m whose disabling cost accuracy.
  double bias_min = 0.1;
  double bias_significance = 4.0;  // |median| > this many standard errors
  int bias_min_points = 40;        // distinct points before a plane can be disabled
  // Three responses to a biased plane, off by default: each helped on some drives and cost on
  // others (docs/experiments.md, "Peers, re-anchoring and blocking", small seeds 3/11/21).
  // Planes.biasPeers: a plane is judged by witnesses, the trajectory (offset 0) and its peers
  // (planes with points in the same window, normals within bias_peer_angle_deg): biased when it
  // disagrees with a strict majority, by its offset from their median; a plane without peers is
  // never moved or disabled (it is the only witness of its direction). Off: by the trajectory.
  bool bias_peers = false;
  double bias_peer_angle_deg = 20.0;
  // Planes.reanchorBiased: a biased plane is first moved onto its points (by its bias, along
  // its normal) and kept; disabled only when found biased again. A disabled plane leaves its
  // direction to visual odometry; a moved one still holds the trajectory along its normal, at
  // the error the trajectory had when the bias was measured.
  bool reanchor_biased = false;
  // Planes.disabledPlanesBlock: a disabled plane, moved by its points' median, still stands for
  // their surface: a point on it is not given to a neighbouring plane whose gate it also passes
  // (a sidewalk 8 cm above a disabled road takes the road's points near the kerb otherwise).
  bool disabled_planes_block = false;
  // Planes.biasCommonMode: a plane's bias is one error shared by all its points, so N points of
  // it in a window must not weigh it N times. With this on, the part of a plane's bias beyond
  // bias_common_allowance (and its witnesses' uncertainty) is a common-mode variance b^2: each of
  // the N_k points of plane k in a window gets N_k b^2 on top of its own variance, so that the
  // plane ties the window to the map no tighter than b, however many points it has (the
  // marginal of a shared offset with prior b). It is kept at its largest value for the run
  // (hysteresis): a wrong plane that pulled the trajectory onto itself looks less biased
  // afterwards, and must not be trusted again for that.
  bool bias_common_mode = false;
  // Metres: a bias within this is free (0.05 = Planes.mapSigma and 0 cut the weight of clean
  // planes whose 2-5 cm "bias" was the trajectory's; 0.08 measured best, docs/experiments.md).
  double bias_common_allowance = 0.08;
  bool bias_common_hold = true;  // keep the largest b of the run (off: the latest window's)
  // Planes.trajectoryConsensus: the trajectory's own offset from the map, estimated per window
  // from the planes that agree on it. A trajectory that drifted along a direction no plane held
  // (a side street after a turn; or one pulled there by a wrong plane) puts the points of every
  // correct plane seen next at the same offset n.e, beyond the gate, so the window BA never
  // pulls it back. With this on, when at least consensus_min_planes planes of about the same
  // normal (within bias_peer_angle_deg), each with consensus_min_points points in the window,
  // agree within consensus_tolerance (or 3 standard errors) on an offset of at least
  // consensus_min_offset, and they outnumber the planes of that normal that agree with the
  // trajectory as it is, the window reports the offset (trajectory_offset()); its supporters
  // are not disabled in that window; and the tracker moves its map by it when two windows in a
  // row agree (Tracker::MakeBaJob). One plane never makes an offset (it could be the wrong one).
  // Only facades (kind "facade", or within 15 degrees of vertical by the map's "up") are
  // witnesses: the road holds the height in every frame, and the horizontal planes of a street
  // (road, sidewalks, kerbs 0.1-0.2 m apart) agree on false vertical offsets (small seed 7's
  // clean map moved 0.9 m down in four steps when they could).
  // On, with 3 planes of 3 points: over small seeds 3, 7, 11, 13 and 21 (clean, oracle and four
  // wrong maps each) the same or better than off but for one map (+5 %); 2 planes of 5 points
  // also moved maps on false offsets (two moved facades agreeing, or two correct ones at a turn),
  // docs/experiments.md ("The planes' consensus on the trajectory's offset").
  bool trajectory_consensus = true;
  int consensus_min_planes = 3;
  int consensus_min_points = 3;
  double consensus_min_offset = 0.08;  // metres
  double consensus_tolerance = 0.05;   // metres
  // Planes considered (with at least bias_min_points) before "most planes disabled" or "no
  // plane ever passes the gate" is reported as a likely wrong map.
  int warn_after_windows = 10;
  // The image-side check of the map at keyframes (crease_check.h: LSD segments against the
  // projected creases of the map; per-keyframe stats) (Planes.creaseCheck).
  bool crease_check = true;
  // Threaded runs only (Planes.creaseCheckOnWorker): the check on the BA worker, at low priority,
  // instead of on the frame thread. Off: on kitti07-like seed 1 (as fast as the frames decode)
  // it made the frame path 1.3x faster (28-29 vs 21-24 fps) but let the frame thread outrun the
  // BA (11-25 instead of 3-5 of ~200 keyframes superseded) and cost 1.15-1.3x in ATE
  // (docs/crease-check.md). At camera rate (10 Hz) the worker has the time and it is the better
  // choice.
  bool crease_check_on_worker = false;
  // The crease gate (Planes.creaseGate, needs crease_check): a point is associated with a plane
  // only if its keypoint lies in the plane's image region and not across a confirmed crease
  // bounding it, in every checked keyframe observing it. Off: the ablation in
  // docs/experiments.md ("LSD crease gate") found no gain.
  bool crease_gate = false;
  // Its min_plane_area and region_margin are replaced by min_plane_area and polygon_margin.
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
  // m^2, bias_common_mode: the plane's common-mode variance b^2, to be multiplied by the number of
  // the plane's points in the window and added to sigma^2 (not included in sigma).
  double common_variance = 0;
};

// Per plane: statistics of its points' signed distances (the visual estimates).
struct PlaneHealth {
  int points = 0;             // distinct points recorded
  double median = 0;          // metres, signed
  double standard_error = 0;  // metres, of the median (robust, from the MAD)
  bool disabled = false;
  bool reanchored = false;  // moved onto its points once (reanchor_biased)
  double shift = 0;         // metres along the normal it was moved by
  double common_bias = 0;   // metres, bias_common_mode: its largest common-mode bias b so far
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
  // FinishRecords before the window's Associate calls.
  void Record(int point_id, const PointEstimate& estimate);
  // Closes the window's records: estimates the trajectory's offset from them
  // (options.trajectory_consensus; zero otherwise or without a consensus) and adds them to the
  // planes' statistics. UpdateHealth calls it when records are pending.
  void FinishRecords();
  // The offset of the last FinishRecords (map frame, metres): the estimated trajectory error e,
  // points sit at n.e off a correct plane. Zero when no consensus.
  const Eigen::Vector3d& trajectory_offset() const { return consensus_.offset; }
  // Drops the point's recorded distance (a point merged into another by map-point fusion: the
  // survivor stands for both, and counting the duplicate would double its weight).
  void ForgetPoint(int point_id);
  // Recomputes the statistics of the planes recorded since the last call, disables biased
  // ones (spdlog warn each) and warns once when the map looks wrong. `associations`: points
  // associated in the window just built. Returns the number of planes disabled by this call.
  int UpdateHealth(int associations);
  // How far the trajectory itself may be off in the map frame (position covariance, m^2, map
  // axes), e.g. right after a map lock: a plane's points then sit off it by n^T e for a camera
  // error e, so the bias test allows n^T C n on top of the median's standard error, and only the
  // part of the bias beyond sqrt(n^T C n) down-weights the plane. Zero (the default): the
  // trajectory is taken as right and every bias is the map's.
  void SetTrajectoryCovariance(const Eigen::Matrix3d& position_covariance_in_map);
  // Forgets every plane's statistics and re-enables the disabled ones: after a correction of the
  // map frame (a lock, a re-registration) the biases seen before it measured the trajectory's
  // error as much as the planes'. A plane that is really wrong is disabled again.
  void ResetHealth();

  // The image-side check at keyframe `keyframe_id` (options.crease_check; CreaseChecker::
  // CheckKeyframe) on level options.crease.lsd_level of its left ORB pyramid. std::nullopt when
  // the check is off or the pyramid has no such level.
  std::optional<CreaseCheckStats> CheckKeyframe(int keyframe_id, const Rigid3d& cam_from_world,
                                                const StereoCamera& camera,
                                                const std::vector<cv::Mat>& left_pyramid);
  struct KeypointView {
    int keyframe_id = 0;
    Eigen::Vector2d keypoint = Eigen::Vector2d::Zero();  // level-0 pixels
  };
  // The crease gate for a point associated with `plane_id` (always true with
  // options.crease_gate off); counts refusals for the current window.
  bool GateAllows(int plane_id, const Eigen::Vector3d& point_in_map,
                  const std::vector<KeypointView>& views);
  // Refusals of the gate in the window last closed by UpdateHealth (region, side), into `stats`.
  void FillGateStats(CreaseCheckStats& stats) const;
  int window_gate_rejections() const {
    return window_gate_rejections_[0] + window_gate_rejections_[1];
  }
  const CreaseChecker* crease_checker() const { return creases_.get(); }
  // The crease check's image of a keyframe (its pyramid level options.crease.lsd_level), empty
  // when the check is off or the pyramid has no such level; and the gate's copy of a check
  // computed elsewhere (CreaseChecker::Compute on the BA worker).
  cv::Mat CreaseCheckImage(const std::vector<cv::Mat>& left_pyramid) const;
  void KeepCreaseCheck(int keyframe_id, KeyframeCreaseCheck check);

  // Plane by id (as in planes.json). Throws std::out_of_range for an unknown id.
  const MapPlane& plane(int id) const;
  const PlaneHealth& health(int id) const;
  // sqrt(rms^2 + map_sigma^2 + bias^2) of an enabled plane, metres.
  double PlaneSigma(int id) const;
  std::size_t size() const { return planes_.size(); }
  int num_disabled() const { return num_disabled_; }      // currently disabled
  int num_reanchored() const { return num_reanchored_; }  // currently moved onto their points

 private:
  struct FlatPlane {
    MapPlane plane;
    Eigen::Vector3d u, v;      // in-plane basis
    IndexedPolygon2d outline;  // in (u, v); fewer than 3 vertices: unbounded
    PlaneHealth health;
    double bias2 = 0;                         // m^2, squared median once enough points
    std::map<int, double> distance_by_point;  // point id -> latest signed distance
    bool touched = false;
    bool facade = false;  // a witness of the trajectory's horizontal offset (consensus)
  };
  bool InsideOutline(const FlatPlane& flat, const Eigen::Vector3d& point) const;
  std::int64_t CellKey(const Eigen::Vector3d& point) const;
  // Calls f(index) for the planes whose cells contain the point; stops when f returns false.
  template <typename F>
  void ForCandidates(const Eigen::Vector3d& point_in_map, F f) const;
  double Variance(const FlatPlane& flat) const;
  // The consensus of the facades' records in pending_ (offset zero when none).
  TrajectoryConsensus ConsensusOffset() const;
  // Signed distance of x from the plane, or, for a disabled plane, from the surface its points
  // showed (the plane moved by their median).
  double SurfaceDistance(const FlatPlane& flat, const Eigen::Vector3d& x) const;

  PlaneAssociationOptions options_;
  std::string map_name_;
  std::vector<FlatPlane> planes_;
  std::unordered_map<int, std::size_t> index_by_id_;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> cells_;
  std::vector<std::size_t> unbounded_;  // planes without an outline: tested everywhere
  Eigen::Matrix3d trajectory_covariance_ = Eigen::Matrix3d::Zero();
  struct PendingRecord {
    std::size_t index;
    int point_id;
    double distance;
  };
  std::vector<PendingRecord> pending_;  // Record calls since the last FinishRecords
  TrajectoryConsensus consensus_;  // of the last FinishRecords (supporters: indices in planes_)
  int num_disabled_ = 0;
  int num_reanchored_ = 0;
  int windows_ = 0;
  long long total_associations_ = 0;
  bool warned_no_association_ = false, warned_most_disabled_ = false;
  std::unique_ptr<CreaseChecker> creases_;  // with options.crease_check
  int gate_rejections_[2] = {0, 0}, window_gate_rejections_[2] = {0, 0};  // region, side
};

}  // namespace planeloc
