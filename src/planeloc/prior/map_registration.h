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
  // Heading grid step (degrees); grown so that the grid has at most max_headings entries.
  double heading_step_deg = 1.0;
  int max_headings = 91;
  // Hough cell of the horizontal shift (metres); grown so that an axis has at most max_cells.
  double shift_cell = 0.25;
  int max_cells = 200;
  // Structure points used (a deterministic subsample of the given ones).
  int max_points = 1500;
  int min_points = 150;
  // Hough peaks refined by Gauss-Newton.
  int num_hypotheses = 8;
  // Planes smaller than this (m^2) are not used.
  double min_plane_area = 8.0;
  // A point counts for a plane when its projection lies in the outline grown by this (metres).
  double outline_margin = 0.5;
  // Standard deviation of a plane of the map (metres), added to its fitted rms.
  double map_sigma = 0.05;
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

  bool NearOutline(const FlatPlane& plane, const Eigen::Vector3d& point, double margin) const;
  void Refine(const std::vector<RegistrationPoint>& points, const RegistrationPrior& prior,
              const std::vector<int>& candidates, Hypothesis& hypothesis) const;

  MapRegistrationOptions options_;
  std::vector<FlatPlane> planes_;
};

}  // namespace planeloc
