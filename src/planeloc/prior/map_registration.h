// Registration of the tracker's stereo structure to the LiDAR plane map: how a run that starts
// from a coarse (GNSS-like) pose finds its pose in the map frame.
//
// The tracker runs as visual odometry in the frame of the given start pose (the "world" frame),
// which differs from the map frame by an unknown rigid correction
//   map_from_world(p) = R (p - c) + c + delta,
// a rotation R about the pivot c (the camera centre where the prior holds) and a shift delta. The
// prior says delta ~ N(0, sigma_horizontal^2 / sigma_vertical^2) and R = yaw(psi) with
// psi ~ N(0, sigma_yaw^2); roll and pitch are known to a degree or so (the road fixes them).
//
// The search has three steps (docs/map-registration.md):
//  1. Height: every point over a ground plane votes for the vertical shift (1-D histogram).
//  2. Heading and horizontal shift: for each heading of a grid over +-3 sigma, every point votes,
//     for every facade it could lie on, for the line of horizontal shifts that puts it on that
//     facade (a Hough transform in shift space). Peaks are hypotheses.
//  3. Each of the best peaks is refined by robust point-to-plane Gauss-Newton in 6 DoF with the
//     prior, and scored by its inliers.
// A hypothesis is accepted only when it is consistent (inlier ratio, residual RMS, margin over the
// best distinct second hypothesis) and well conditioned: the marginal standard deviation of each
// named degree of freedom at the current camera (along-track, lateral, vertical, roll, pitch,
// yaw), from the point-to-plane information alone, must be below a threshold. On a straight
// street the road and the parallel facades leave along-track unobserved: that is a partial lock
// (the other five DoF are corrected, along-track keeps the prior) until a plane facing the car
// (a corner, a wall across the road) completes it.
#pragma once

#include <Eigen/Core>
#include <array>
#include <string>
#include <vector>

#include "planeloc/geometry/lie.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/plane_map.h"

namespace planeloc {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

// The degrees of freedom named in the vehicle's frame at the current camera.
enum RegistrationDof { kAlongTrack = 0, kLateral, kVertical, kRoll, kPitch, kYaw, kNumDofs };
const char* RegistrationDofName(int dof);

enum class MapLock {
  kSearching,  // not registered: visual odometry in the start pose's frame
  kPartial,    // all DoF but along-track registered (road + parallel facades)
  kLocked,     // all six DoF registered
};
const char* MapLockName(MapLock lock);

struct MapRegistrationOptions {
  // Search range of the heading / shift grids, in prior standard deviations.
  double search_sigmas = 3.0;
  // Metres added to each half range of the horizontal shift grid (a prior of zero horizontal
  // sigma still searches +-1 m).
  double search_margin = 1.0;
  // Metres added to how far (prior shift + heading x lever arm) the structure can reach: planes
  // whose outline box is farther from the structure's box are not candidates.
  double reach_margin = 2.0;
  // A plane within this angle (degrees) of horizontal is ground; within this angle of vertical,
  // a facade (a Hough voter). Also what UpDirection averages.
  double ground_max_tilt_deg = 15.0;
  double facade_max_tilt_deg = 15.0;
  // Height vote (step 1): metres added to search_sigmas x the vertical sigma, and the histogram's
  // bin (metres).
  double vertical_search_margin = 0.3;
  double vertical_bin = 0.05;
  // Points within this distance (metres) of a ground plane after the height vote vote for no
  // facade.
  double ground_band = 0.3;
  // Heading grid step (degrees); grown so that the grid has at most max_headings entries.
  double heading_step_deg = 1.0;
  int max_headings = 91;
  // Hough cell of the horizontal shift (metres); grown so that an axis has at most max_cells.
  double shift_cell = 0.25;
  int max_cells = 200;
  // Local maxima of the Hough accumulator kept per heading.
  int peaks_per_heading = 3;
  // Structure points used (a deterministic subsample of the given ones); the best hypothesis
  // also needs min_points / 2 inliers.
  int max_points = 1500;
  int min_points = 150;
  // Hough peaks refined by Gauss-Newton.
  int num_hypotheses = 8;
  // Peaks closer than this to a kept one (metres of shift and degrees of heading, both) are
  // duplicates and not refined.
  double duplicate_peak_shift = 1.0;
  double duplicate_peak_angle_deg = 2.0;
  // Planes smaller than this (m^2) are not used.
  double min_plane_area = 8.0;
  // A point counts for a plane when its projection lies in the outline grown by this (metres).
  double outline_margin = 0.5;
  // Standard deviation of a plane of the map (metres), added to its fitted rms.
  double map_sigma = 0.05;
  // Refinement (step 3): one Gauss-Newton iteration per entry, each associating the points with
  // planes within this gate (metres) + inlier_sigmas sigma; a shrinking gate, 0 at the end.
  std::vector<double> association_gates = {1.0,  1.0,  1.0,  0.5, 0.5, 0.5,
                                           0.25, 0.25, 0.25, 0.0, 0.0, 0.0};
  // Huber threshold of the refinement, in sigmas of the point-to-plane distance.
  double huber_sigmas = 2.0;
  // Added to the prior covariance's diagonal (m^2 and rad^2) before inverting it, so that an
  // exact (zero-sigma) DoF becomes a very stiff one instead of a singular one.
  double prior_variance_floor = 1e-10;
  // Consistency: a point is an inlier within this many sigma of its plane (and its sigma is
  // floored at min_point_sigma metres).
  double inlier_sigmas = 3.0;
  double min_point_sigma = 0.05;
  double min_inlier_ratio = 0.25;
  // Whitened RMS of the inliers' point-to-plane distances (about 1 when the sigmas are right).
  double max_whitened_rms = 1.5;
  // Truncated chi2 of the best distinct hypothesis minus the best's (over noise_inflation^2).
  double min_margin = 10.0;
  // Hypotheses closer than this (metres / degrees in the constrained DoF) are the same one.
  double distinct_shift = 0.5;
  double distinct_angle_deg = 1.5;
  // Conditioning: a DoF is constrained when its marginal standard deviation from the
  // point-to-plane information (point noise inflated by `noise_inflation` for the correlated
  // errors of visual structure) is below these.
  double max_dof_sigma = 0.1;       // metres
  double max_dof_sigma_deg = 0.5;   // degrees, heading
  double max_tilt_sigma_deg = 0.5;  // degrees, roll and pitch (10 m away: 9 cm)
  double noise_inflation = 3.0;
  // The covariance is regularized by a prior of this sigma (metres; rotations x 10 m) so that an
  // unobserved direction gets a large, finite variance (docs/map-registration.md).
  double regularizer_sigma = 100.0;
  // Above these marginal sigmas (metres; radians for roll, pitch and yaw) the regularizer, not
  // the data, sets the value: the DoF is reported unobserved (an infinite sigma).
  double unobserved_shift_sigma = 10.0;
  double unobserved_angle_sigma = 0.5;
  // Prior on roll and pitch (degrees): the start pose's tilt, refined by the road.
  double sigma_tilt_deg = 1.0;

  void Check() const;  // throws OptionsError naming the field
};

// The prior on the correction map_from_world, as a covariance of xi = (delta, omega) with
// R = Exp(omega), both in world axes, about `pivot_in_world`.
struct RegistrationPrior {
  Eigen::Vector3d pivot_in_world = Eigen::Vector3d::Zero();
  Eigen::Vector3d up_in_world = -Eigen::Vector3d::UnitY();  // KITTI camera frame: y down
  Matrix6d covariance = Matrix6d::Identity();

  // sigma_horizontal / sigma_vertical in metres, sigma_yaw / sigma_tilt in radians.
  static RegistrationPrior FromSigmas(const Eigen::Vector3d& pivot, const Eigen::Vector3d& up,
                                      double sigma_horizontal, double sigma_vertical,
                                      double sigma_yaw, double sigma_tilt);
  // Anisotropic: along-track (horizontal part of `forward`), lateral and vertical shift sigmas.
  static RegistrationPrior FromVehicleSigmas(const Eigen::Vector3d& pivot,
                                             const Eigen::Vector3d& up,
                                             const Eigen::Vector3d& forward, double sigma_along,
                                             double sigma_lateral, double sigma_vertical,
                                             double sigma_yaw, double sigma_tilt);
};

struct RegistrationPoint {
  Eigen::Vector3d point_in_world;
  double sigma = 0.1;  // metres, position standard deviation (depth-dominated)
};

struct RegistrationResult {
  MapLock lock = MapLock::kSearching;
  // The correction to apply (identity unless lock != kSearching): p_map = map_from_world * p.
  Rigid3d map_from_world;
  // The best hypothesis, whether accepted or not (for the stats).
  Rigid3d candidate_map_from_world;
  // Marginal standard deviations of the named DoF at the current camera (metres / radians), from
  // the point-to-plane information of the best hypothesis; +inf when unobserved.
  std::array<double, kNumDofs> dof_sigma{};
  std::array<bool, kNumDofs> constrained{};
  // Covariance of the current camera's position in the map frame (m^2), from the same
  // information; an unobserved direction gets a large (regularized, ~100 m) variance.
  Eigen::Matrix3d camera_position_covariance = Eigen::Matrix3d::Identity() * 1e4;
  Vector6d information_eigenvalues = Vector6d::Zero();  // metric units (rotation x 10 m)
  // The best hypothesis at the current camera (prior/lock_fusion.h), whether accepted or not:
  // the camera's shift (metres) and the rotation vector (radians) in the vehicle axes at the
  // camera, the rows of `vehicle_axes` (along-track, lateral, up; map axes), with the
  // point-to-plane information of the same coordinates (inflated noise, no prior).
  Vector6d correction_at_camera = Vector6d::Zero();
  Matrix6d information_at_camera = Matrix6d::Zero();
  Eigen::Matrix3d vehicle_axes = Eigen::Matrix3d::Identity();
  Eigen::Vector3d camera_in_world = Eigen::Vector3d::Zero();
  int points = 0;   // structure points used
  int inliers = 0;  // of the best hypothesis
  double inlier_ratio = 0;
  double rms = 0;           // metres, inliers' point-to-plane distances
  double whitened_rms = 0;  // the same, each divided by its point's sigma
  double margin = 0;        // chi2 margin over the best distinct hypothesis (inf without one)
  int hypotheses = 0;       // refined
  std::string reason;       // why it is not (fully) locked
};

class MapRegistration {
 public:
  // Keeps the planes with at least options.min_plane_area; `up_in_map` from the ground planes.
  MapRegistration(const PlaneMap& planes, const MapRegistrationOptions& options);

  // Registers `points` (world frame) under `prior`. `camera_in_world` is the current camera
  // (world_from_cam): the DoF are named and their sigmas reported there.
  RegistrationResult Register(const std::vector<RegistrationPoint>& points,
                              const RegistrationPrior& prior,
                              const Rigid3d& world_from_camera) const;

  // The map's "up": the area-weighted normal of its ground planes, oriented like `hint`; `hint`
  // when the map has none.
  Eigen::Vector3d UpDirection(const Eigen::Vector3d& hint) const;
  std::size_t num_planes() const { return planes_.size(); }

 private:
  struct FlatPlane {
    int id = 0;
    Plane plane;
    double sigma = 0.05;                   // metres: rms + map sigma
    Eigen::Vector3d u, v;                  // in-plane basis
    std::vector<Eigen::Vector3d> polygon;  // outline in map coordinates
    std::vector<Eigen::Vector2d> ring;     // outline in (u, v); empty: unbounded
    Eigen::Vector3d lo, hi;                // bounding box of the outline
    bool ground = false;
  };
  struct Hypothesis;
  // The prior as a search space: up, pivot, the vertical and heading sigmas, the shift grid.
  struct SearchSpace;
  // The planes the structure can reach under the prior, and which of them are ground / facades.
  struct PlaneSets;
  // A point's plane (index into planes_, -1: none) and the sigma of its distance to it.
  struct PlaneMatch;

  bool NearOutline(const FlatPlane& plane, const Eigen::Vector3d& point, double margin) const;

  // The steps of Register (docs/map-registration.md), in order.
  std::vector<RegistrationPoint> Subsample(const std::vector<RegistrationPoint>& all_points) const;
  SearchSpace PriorSearchSpace(const RegistrationPrior& prior) const;
  PlaneSets ReachablePlanes(const std::vector<RegistrationPoint>& points,
                            const SearchSpace& search) const;
  // Step 1: the vertical shift voted by the points over a ground plane (`near_ground`: which).
  double VoteHeight(const std::vector<RegistrationPoint>& points, const SearchSpace& search,
                    const std::vector<int>& grounds, std::vector<bool>& near_ground) const;
  // The points, shifted vertically, that are not on the ground: step 2's voters.
  std::vector<Eigen::Vector3d> FacadeVoters(const std::vector<RegistrationPoint>& points,
                                            const SearchSpace& search,
                                            const std::vector<int>& grounds,
                                            const std::vector<bool>& near_ground,
                                            double vertical_shift) const;
  // Step 2: the distinct Hough peaks over heading x horizontal shift, plus the prior's mean.
  std::vector<Hypothesis> VoteHeadingAndShiftHypotheses(
      const std::vector<Eigen::Vector3d>& facade_voters, const SearchSpace& search,
      const std::vector<int>& facades, double vertical_shift) const;
  // Steps 3 and 4: refines and scores every hypothesis, then sorts them by cost (stable).
  void RefineAndRank(const std::vector<RegistrationPoint>& points, const RegistrationPrior& prior,
                     const std::vector<int>& candidates, std::vector<Hypothesis>& hypotheses) const;
  // Robust point-to-plane Gauss-Newton (optim/robust_gauss_newton.h) with the prior, then Score.
  void Refine(const std::vector<RegistrationPoint>& points, const RegistrationPrior& prior,
              const std::vector<int>& candidates, Hypothesis& hypothesis) const;
  // Each point's nearest candidate plane within `gate` + inlier_sigmas sigma under `hypothesis`.
  void AssociatePlanes(const std::vector<RegistrationPoint>& points, const Eigen::Vector3d& pivot,
                       const std::vector<int>& candidates, const Hypothesis& hypothesis,
                       double gate, std::vector<PlaneMatch>& matches) const;
  // The truncated chi2 cost, inliers, rms and point-to-plane information of `hypothesis`.
  void Score(const std::vector<RegistrationPoint>& points, const Eigen::Vector3d& pivot,
             const std::vector<PlaneMatch>& matches, Hypothesis& hypothesis) const;
  // Conditioning of the best hypothesis at the camera: fills the result's vehicle axes,
  // correction and information at the camera, DoF sigmas, constrained DoF and eigenvalues.
  // Returns each named DoF's direction (map axes).
  std::array<Eigen::Vector3d, kNumDofs> ConditionAtCamera(const Hypothesis& best,
                                                          const SearchSpace& search,
                                                          const Rigid3d& world_from_camera,
                                                          RegistrationResult& result) const;
  // The cost margin of the best (ranked.front()) over the best hypothesis that differs from it
  // in a constrained DoF at the camera, over noise_inflation^2; +inf without one.
  double MarginOverDistinct(const std::vector<Hypothesis>& ranked, const Eigen::Vector3d& pivot,
                            const Eigen::Vector3d& camera,
                            const std::array<Eigen::Vector3d, kNumDofs>& named,
                            const std::array<bool, kNumDofs>& constrained) const;
  // Acceptance: consistency, margin and conditioning decide the lock and the reason.
  void Verdict(const Hypothesis& best, const Eigen::Vector3d& pivot,
               RegistrationResult& result) const;

  MapRegistrationOptions options_;
  double ground_cos_;  // cos(ground_max_tilt_deg): |n . up| above it is ground
  double facade_sin_;  // sin(facade_max_tilt_deg): |n . up| below it is a facade
  std::vector<FlatPlane> planes_;
};

}  // namespace planeloc
