// Seeded synthetic scenes for the optim tests and benchmark (header-only, test support).
//
// A KITTI-like stereo camera drives along +z of the world (camera x right, y down, z forward);
// points lie on three planes (road y = 1.6, walls x = -6 and x = +6) or off any plane.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <random>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/lie.h"
#include "planeloc/geometry/plane.h"
#include "planeloc/geometry/rigid3.h"

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

}  // namespace planeloc::test
