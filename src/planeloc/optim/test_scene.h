// Seeded synthetic scenes for the optim tests and benchmark (header-only, test support).
//
// A KITTI-like stereo camera drives along +z of the world (camera x right, y down, z forward);
// points lie on three planes (road y = 1.6, walls x = -6 and x = +6) or off any plane.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <random>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/lie.h"
#include "planeloc/geometry/plane.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/optim/pose_optimizer.h"
#include "planeloc/optim/window_ba.h"

namespace planeloc::test {

inline StereoCamera KittiLikeCamera() {
  StereoCamera c;
  c.fx = 718.856;
  c.fy = 718.856;
  c.cx = 607.1928;
  c.cy = 185.2157;
  c.baseline = 0.537;
  c.width = 1241;
  c.height = 376;
  return c;
}

// The three scene planes in world coordinates (n . x + d = 0).
inline std::vector<Plane> ScenePlanes() {
  return {Plane(Eigen::Vector3d(0, -1, 0), 1.6),   // road, y = 1.6 (below the camera)
          Plane(Eigen::Vector3d(1, 0, 0), 6.0),    // left wall, x = -6
          Plane(Eigen::Vector3d(-1, 0, 0), 6.0)};  // right wall, x = +6
}

// A random point: plane_index in [0, 3) on that plane, -1 off-plane. Spread along z in
// [z_min, z_max] metres.
inline Eigen::Vector3d RandomScenePoint(std::mt19937& rng, int plane_index, double z_min,
                                        double z_max) {
  std::uniform_real_distribution<double> uz(z_min, z_max), ux(-5.5, 5.5), uy(-3.0, 1.5);
  const double z = uz(rng);
  switch (plane_index) {
    case 0:
      return {ux(rng), 1.6, z};
    case 1:
      return {-6.0, uy(rng), z};
    case 2:
      return {6.0, uy(rng), z};
    default:
      return {ux(rng), uy(rng), z};
  }
}

// Small random rigid perturbation: rotation angle ~ rot_sigma (rad), translation ~ trans_sigma (m)
// per axis, applied on the left (in the camera frame of cam_from_world).
inline Rigid3d Perturb(const Rigid3d& cam_from_world, double rot_sigma, double trans_sigma,
                       std::mt19937& rng) {
  std::normal_distribution<double> nr(0.0, rot_sigma), nt(0.0, trans_sigma);
  const Eigen::Vector3d omega(nr(rng), nr(rng), nr(rng));
  const Eigen::Vector3d dt(nt(rng), nt(rng), nt(rng));
  return Rigid3d(Eigen::Matrix3d(ExpSO3(omega)), dt) * cam_from_world;
}

struct PoseScene {
  StereoCamera camera = KittiLikeCamera();
  Rigid3d cam_from_world_true;
  std::vector<PoseObservation> observations;
  std::vector<bool> is_outlier;
};

// `num` points seen by a camera at a known pose, 1 px Gaussian noise, a fraction of gross
// outliers (20-60 px off), depths 3 m .. max_depth, stereo for points closer than 40 baselines
// (21.5 m), mono beyond.
inline PoseScene MakePoseScene(int num, double outlier_fraction, unsigned seed,
                               double max_depth = 60.0) {
  PoseScene s;
  std::mt19937 rng(seed);
  s.cam_from_world_true =
      Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY())),
              Eigen::Vector3d(0.5, -0.2, -3.0));
  const Rigid3d world_from_cam = s.cam_from_world_true.Inverse();
  std::uniform_real_distribution<double> uu(0, s.camera.width - 1), uv(0, s.camera.height - 1);
  std::uniform_real_distribution<double> depth(3.0, max_depth), unit(0.0, 1.0), sign(-1.0, 1.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  while (static_cast<int>(s.observations.size()) < num) {
    const Eigen::Vector3d point_in_cam =
        s.camera.Unproject(Eigen::Vector2d(uu(rng), uv(rng)), depth(rng));
    const Eigen::Vector3d stereo = *s.camera.ProjectStereo(point_in_cam);
    PoseObservation o;
    o.point_in_world = world_from_cam * point_in_cam;
    o.u_left = stereo.x() + noise(rng);
    o.v = stereo.y() + noise(rng);
    const bool close = point_in_cam.z() < 40 * s.camera.baseline;
    o.u_right = close ? stereo.z() + noise(rng) : -1.0;
    const bool outlier = unit(rng) < outlier_fraction;
    if (outlier) {
      o.u_left += (sign(rng) > 0 ? 1 : -1) * (20 + 40 * unit(rng));
      o.v += (sign(rng) > 0 ? 1 : -1) * (20 + 40 * unit(rng));
      if (close) o.u_right = o.u_left - (stereo.x() - stereo.z());
    }
    s.observations.push_back(o);
    s.is_outlier.push_back(outlier);
  }
  return s;
}

// Ground truth and a perturbed BA problem of a camera driving along a road between two walls.
struct WindowScene {
  StereoCamera camera = KittiLikeCamera();
  std::vector<Rigid3d> cam_from_world_true;  // by keyframe id = index
  std::vector<Eigen::Vector3d> point_true;   // by point id = index
  WindowProblem problem;                     // perturbed initial values
};

struct WindowSceneConfig {
  int keyframes = 8;
  double spacing = 1.5;        // metres between keyframes along z
  int points_per_plane = 150;  // on each of the 3 planes
  int off_plane_points = 150;
  double pixel_noise = 1.0;
  double pose_rot_sigma = 0.005, pose_trans_sigma = 0.1;  // initial pose perturbation
  double point_sigma = 0.3;                               // metres, initial point perturbation
  double scale = 1.0;  // initial trajectory/structure scaled about keyframe 0 (drift)
  bool mono_only = false;
  unsigned seed = 1;
};

inline WindowScene MakeWindowScene(const WindowSceneConfig& c) {
  WindowScene s;
  std::mt19937 rng(c.seed);
  std::normal_distribution<double> noise(0.0, c.pixel_noise), point_noise(0.0, c.point_sigma);
  for (int k = 0; k < c.keyframes; ++k) {
    const Eigen::Quaterniond yaw(Eigen::AngleAxisd(0.02 * k, Eigen::Vector3d::UnitY()));
    const Eigen::Vector3d centre(0.1 * std::sin(k), 0.0, c.spacing * k);
    s.cam_from_world_true.push_back(Rigid3d(yaw, centre).Inverse());
  }
  const double z_max = c.spacing * c.keyframes + 35.0;
  for (int plane = 0; plane < 4; ++plane) {
    const int count = plane < 3 ? c.points_per_plane : c.off_plane_points;
    for (int i = 0; i < count; ++i) {
      s.point_true.push_back(RandomScenePoint(rng, plane < 3 ? plane : -1, 4.0, z_max));
      WindowPoint p;
      p.id = static_cast<int>(s.point_true.size()) - 1;
      if (plane < 3) p.plane_id = plane;
      s.problem.points.push_back(p);
    }
  }
  const std::vector<Plane> planes = ScenePlanes();
  for (int i = 0; i < 3; ++i) s.problem.planes.push_back({i, planes[i]});

  // Initial values: scale drift about keyframe 0's centre, then random perturbations.
  const Eigen::Vector3d origin = s.cam_from_world_true[0].Inverse().translation;
  for (int k = 0; k < c.keyframes; ++k) {
    const Rigid3d world_from_cam = s.cam_from_world_true[k].Inverse();
    Rigid3d scaled(world_from_cam.rotation,
                   origin + c.scale * (world_from_cam.translation - origin));
    Rigid3d initial = scaled.Inverse();
    if (k > 0) initial = Perturb(initial, c.pose_rot_sigma, c.pose_trans_sigma, rng);
    s.problem.keyframes.push_back({k, initial, k == 0});
  }
  for (WindowPoint& p : s.problem.points) {
    p.point_in_world = origin + c.scale * (s.point_true[p.id] - origin) +
                       Eigen::Vector3d(point_noise(rng), point_noise(rng), point_noise(rng));
  }
  for (int k = 0; k < c.keyframes; ++k) {
    for (size_t j = 0; j < s.point_true.size(); ++j) {
      const Eigen::Vector3d x = s.cam_from_world_true[k] * s.point_true[j];
      if (x.z() < 2.0 || x.z() > 45.0) continue;
      const Eigen::Vector3d uvu = *s.camera.ProjectStereo(x);
      if (!s.camera.InImage(uvu.head<2>())) continue;
      WindowObservation o;
      o.keyframe_id = k;
      o.point_id = static_cast<int>(j);
      o.u_left = uvu.x() + noise(rng);
      o.v = uvu.y() + noise(rng);
      const bool stereo = !c.mono_only && x.z() < 40 * s.camera.baseline;
      o.u_right = stereo ? uvu.z() + noise(rng) : -1.0;
      s.problem.observations.push_back(o);
    }
  }
  return s;
}

}  // namespace planeloc::test
