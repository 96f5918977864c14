// Test-only synthetic LiDAR-map-like clouds: noisy planar rectangles (ground, facades), boxes
// (cars), volumetric blobs (tree crowns) and scattered clutter, with the GT planes. Header-only so
// tests and the benchmark share it without adding to the library.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <random>
#include <vector>

#include "planeloc/geometry/plane.h"

namespace planeloc::testing {

struct SyntheticScene {
  std::vector<Eigen::Vector3d> points;
  std::vector<int> gt_label;  // index into gt_planes, -1 for clutter / car / tree
  std::vector<Plane> gt_planes;
  std::vector<double> gt_areas;  // m^2 of each GT plane's sampled rectangle
};

class SceneBuilder {
 public:
  SceneBuilder(double spacing, double noise, std::uint32_t seed)
      : spacing_(spacing), noise_(noise), rng_(seed) {}

  // Rectangle origin + a*u + b*v, a in [0, len_u], b in [0, len_v] (u, v orthonormal), jittered
  // grid samples with Gaussian noise along all axes. label: true to register it as a GT plane.
  void Rectangle(const Eigen::Vector3d& origin, const Eigen::Vector3d& u, double len_u,
                 const Eigen::Vector3d& v, double len_v, bool gt) {
    const int label = gt ? static_cast<int>(scene_.gt_planes.size()) : -1;
    if (gt) {
      scene_.gt_planes.push_back(Plane::FromPointAndNormal(origin, u.cross(v)));
      scene_.gt_areas.push_back(len_u * len_v);
    }
    std::uniform_real_distribution<double> jitter(-0.3 * spacing_, 0.3 * spacing_);
    for (double a = 0.5 * spacing_; a < len_u; a += spacing_) {
      for (double b = 0.5 * spacing_; b < len_v; b += spacing_) {
        Add(origin + (a + jitter(rng_)) * u + (b + jitter(rng_)) * v, label);
      }
    }
  }

  // Axis-aligned box surface (a car): never a GT plane.
  void Box(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
    const Eigen::Vector3d size = hi - lo;
    const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                          z = Eigen::Vector3d::UnitZ();
    Rectangle(lo, x, size.x(), z, size.z(), false);
    Rectangle(lo + size.y() * y, x, size.x(), z, size.z(), false);
    Rectangle(lo, y, size.y(), z, size.z(), false);
    Rectangle(lo + size.x() * x, y, size.y(), z, size.z(), false);
    Rectangle(lo + size.z() * z, x, size.x(), y, size.y(), false);
  }

  // Uniform points in a ball (a tree crown), density like the surfaces per unit volume.
  void Blob(const Eigen::Vector3d& center, double radius, int count) {
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (int added = 0; added < count;) {
      const Eigen::Vector3d p(unit(rng_), unit(rng_), unit(rng_));
      if (p.squaredNorm() > 1.0) continue;
      Add(center + radius * p, -1);
      ++added;
    }
  }

  // Ground (z = 0), two facades and clutter: a small street corner.
  static SyntheticScene StreetCorner(double spacing, double noise, std::uint32_t seed) {
    SceneBuilder builder(spacing, noise, seed);
    const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                          z = Eigen::Vector3d::UnitZ();
    builder.Rectangle({-10, -10, 0}, x, 16.0, y, 18.0, true);                 // ground
    builder.Rectangle({6, -10, 0}, y, 18.0, z, 7.0, true);                    // facade x = 6
    builder.Rectangle({-10, 8, 0}, x, 16.0, z, 5.0, true);                    // facade y = 8
    builder.Rectangle({-8, -8, 0}, (x + y).normalized(), 6.0, z, 4.0, true);  // oblique wall
    builder.Box({-2, -4, 0.2}, {2.5, -2.2, 1.6});                             // a car
    builder.Blob({-5, 3, 4}, 1.5, 4000);                                      // a tree crown
    return builder.scene_;
  }

  SyntheticScene& scene() { return scene_; }

 private:
  void Add(const Eigen::Vector3d& p, int label) {
    std::normal_distribution<double> gauss(0.0, noise_);
    scene_.points.push_back(p + Eigen::Vector3d(gauss(rng_), gauss(rng_), gauss(rng_)));
    scene_.gt_label.push_back(label);
  }

  double spacing_;
  double noise_;
  std::mt19937 rng_;
  SyntheticScene scene_;
};

}  // namespace planeloc::testing
