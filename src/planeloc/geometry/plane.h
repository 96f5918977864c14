// An infinite plane n . x + d = 0 with |n| = 1, expressed in the frame its name says
// (e.g. `plane_in_map`). Signed distance of x: n . x + d.
#pragma once

#include <Eigen/Core>
#include <utility>
#include <vector>

#include "planeloc/geometry/rigid3.h"

namespace planeloc {

struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit
  double d = 0.0;                                     // metres

  Plane() = default;
  // Normalizes (normal, d) jointly; throws std::invalid_argument for a zero normal.
  Plane(const Eigen::Vector3d& normal, double d);
  static Plane FromPointAndNormal(const Eigen::Vector3d& point, const Eigen::Vector3d& normal);
  // Total-least-squares fit (smallest eigenvector of the covariance); needs >= 3 points not on a
  // line, else throws std::invalid_argument.
  static Plane Fit(const std::vector<Eigen::Vector3d>& points);

  double SignedDistance(const Eigen::Vector3d& point) const { return normal.dot(point) + d; }
  Eigen::Vector3d Project(const Eigen::Vector3d& point) const {
    return point - SignedDistance(point) * normal;
  }
  // The same plane with the opposite orientation.
  Plane Flipped() const { return Plane(-normal, -d); }
  // Expresses this plane (given in frame A) in frame B: b_from_a maps points of A to B.
  Plane Transformed(const Rigid3d& b_from_a) const;
  // Angle between the normals in radians, orientation-insensitive (in [0, pi/2]).
  double AngleTo(const Plane& other) const;
  // Unit in-plane directions (u, v) with u x v = normal: 2-D coordinates (x.u, x.v) on the plane.
  std::pair<Eigen::Vector3d, Eigen::Vector3d> InPlaneBasis() const;
};

// Crossing-number test of q against a closed ring (any orientation, no repeated last vertex).
bool InsidePolygon2d(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& q);
// Inside the ring, or within `margin` of one of its edges (an outline grown by the margin).
bool InsideOrNearPolygon2d(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& q,
                           double margin);

// InsideOrNearPolygon2d for many queries against one ring: the edges are binned into horizontal
// slabs, so a query tests only the edges whose y-range meets [q.y - margin, q.y + margin]
// instead of all of them (map outlines have tens to hundreds of vertices). Same answer as
// InsideOrNearPolygon2d: the same per-edge arithmetic on the edges that can matter.
class IndexedPolygon2d {
 public:
  IndexedPolygon2d() = default;
  explicit IndexedPolygon2d(std::vector<Eigen::Vector2d> ring);

  // False for a ring of fewer than 3 vertices (as InsideOrNearPolygon2d on an empty ring).
  bool InsideOrNear(const Eigen::Vector2d& q, double margin) const;
  const std::vector<Eigen::Vector2d>& ring() const { return ring_; }

 private:
  int Slab(double y) const;  // unclamped

  std::vector<Eigen::Vector2d> ring_;
  double min_y_ = 0, slab_height_ = 1;
  // Edge e joins ring_[e] and ring_[e - 1] (ring_[n - 1] for e = 0), as InsidePolygon2d walks.
  std::vector<std::vector<int>> slab_edges_;
};

}  // namespace planeloc
