// A straight street of planes and the stereo structure a drive along it reconstructs: the fixture
// of the registration's and the lock fusion's tests.
#pragma once

#include <Eigen/Geometry>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "planeloc/io/plane_map.h"
#include "planeloc/prior/map_registration.h"

namespace planeloc::street_for_test {

constexpr double kDegree = std::numbers::pi / 180.0;
inline const Eigen::Vector3d kUp(0, -1, 0);  // KITTI camera world: y down

inline MapPlane MakePlane(int id, const Plane& plane, std::vector<Eigen::Vector3d> polygon,
                          const std::string& kind) {
  MapPlane p;
  p.id = id;
  p.plane_in_map = plane;
  p.polygon = std::move(polygon);
  p.area = 100;
  p.kind = kind;
  p.rms = 0.01;
  return p;
}

// A straight street along +z: the road (y = 1.65), facades at x = -7 and x = +7, and optionally
// a wall across the road at z = 70 (what a car sees before a T junction).
inline PlaneMap Street(bool cross_wall) {
  PlaneMap map;
  map.planes.push_back(MakePlane(0, Plane(Eigen::Vector3d(0, -1, 0), 1.65),
                                 {{-7, 1.65, -10}, {7, 1.65, -10}, {7, 1.65, 70}, {-7, 1.65, 70}},
                                 "ground"));
  map.planes.push_back(MakePlane(1, Plane(Eigen::Vector3d(1, 0, 0), 7.0),
                                 {{-7, -8, -10}, {-7, 1.65, -10}, {-7, 1.65, 70}, {-7, -8, 70}},
                                 "facade"));
  map.planes.push_back(MakePlane(2, Plane(Eigen::Vector3d(-1, 0, 0), 7.0),
                                 {{7, -8, -10}, {7, 1.65, -10}, {7, 1.65, 70}, {7, -8, 70}},
                                 "facade"));
  if (cross_wall) {
    map.planes.push_back(MakePlane(3, Plane(Eigen::Vector3d(0, 0, -1), 70.0),
                                   {{-7, -8, 70}, {7, -8, 70}, {7, 1.65, 70}, {-7, 1.65, 70}},
                                   "facade"));
  }
  return map;
}

// Points as stereo would reconstruct them from a drive along z in [0, z_end]: on the road, on
// both facades (up to 25 m ahead), on the cross wall if asked, plus clutter; each with noise of
// 3 cm. Returned in the map frame.
inline std::vector<Eigen::Vector3d> StreetStructure(double z_end, int wall_points,
                                                    std::mt19937& rng) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.03);
  std::vector<Eigen::Vector3d> points;
  auto jitter = [&](Eigen::Vector3d p) {
    return Eigen::Vector3d(p + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  };
  const double z_max = z_end + 25.0;
  for (int i = 0; i < 300; ++i) {
    points.push_back(jitter({-6.5 + 13 * unit(rng), 1.65, z_max * unit(rng)}));
  }
  for (int i = 0; i < 300; ++i) {
    const double x = i % 2 ? 7.0 : -7.0;
    points.push_back(jitter({x, 1.4 - 8 * unit(rng), z_max * unit(rng)}));
  }
  for (int i = 0; i < wall_points; ++i) {
    points.push_back(jitter({-6.5 + 13 * unit(rng), 1.4 - 8 * unit(rng), 70.0}));
  }
  for (int i = 0; i < 150; ++i) {  // trees, cars: on no plane
    points.push_back({-5 + 10 * unit(rng), -3 + 4.5 * unit(rng), z_max * unit(rng)});
  }
  return points;
}

// The start pose's error: the world (VO) frame is the map frame moved by the inverse of this.
inline Rigid3d TrueMapFromWorld(double yaw_deg, const Eigen::Vector3d& shift) {
  return Rigid3d(Eigen::Matrix3d(Eigen::AngleAxisd(yaw_deg * kDegree, kUp)), shift);
}

inline std::vector<RegistrationPoint> InWorld(const std::vector<Eigen::Vector3d>& map_points,
                                              const Rigid3d& map_from_world) {
  const Rigid3d world_from_map = map_from_world.Inverse();
  std::vector<RegistrationPoint> points;
  for (const Eigen::Vector3d& p : map_points) points.push_back({world_from_map * p, 0.05});
  return points;
}

// Camera 40 m down the street, looking along it; its pose in the (wrong) world frame.
inline Rigid3d CameraInWorld(const Rigid3d& map_from_world) {
  return map_from_world.Inverse() * Rigid3d(Eigen::Quaterniond::Identity(), {0, 0, 40});
}

inline RegistrationPrior DefaultPrior() {
  // The start camera at the origin of the world frame: sigmas 2 m, 0.5 m, 5 deg.
  return RegistrationPrior::FromSigmas(Eigen::Vector3d::Zero(), kUp, 2.0, 0.5, 5 * kDegree,
                                       1 * kDegree);
}

}  // namespace planeloc::street_for_test
