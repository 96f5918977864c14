#include "planeloc/geometry/plane.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace planeloc {

Plane::Plane(const Eigen::Vector3d& n, double offset) {
  const double norm = n.norm();
  if (!(norm > 1e-12) || !std::isfinite(norm)) throw std::invalid_argument("plane: zero normal");
  normal = n / norm;
  d = offset / norm;
}

Plane Plane::FromPointAndNormal(const Eigen::Vector3d& point, const Eigen::Vector3d& n) {
  const Eigen::Vector3d unit = n.normalized();
  return Plane(unit, -unit.dot(point));
}

Plane Plane::Fit(const std::vector<Eigen::Vector3d>& points) {
  if (points.size() < 3) throw std::invalid_argument("plane fit needs at least 3 points");
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  for (const auto& p : points) covariance += (p - centroid) * (p - centroid).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
  // Eigenvalues ascending: a plane needs the middle one clearly above zero (points not on a line).
  if (solver.eigenvalues()(1) <= 1e-12 * std::max(1.0, solver.eigenvalues()(2))) {
    throw std::invalid_argument("plane fit: points are collinear");
  }
  return FromPointAndNormal(centroid, solver.eigenvectors().col(0));
}

Plane Plane::Transformed(const Rigid3d& b_from_a) const {
  const Eigen::Vector3d normal_in_b = b_from_a.rotation * normal;
  return Plane(normal_in_b, d - normal_in_b.dot(b_from_a.translation));
}

double Plane::AngleTo(const Plane& other) const {
  return std::acos(std::clamp(std::abs(normal.dot(other.normal)), 0.0, 1.0));
}

std::pair<Eigen::Vector3d, Eigen::Vector3d> Plane::InPlaneBasis() const {
  const Eigen::Vector3d helper =
      std::abs(normal.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d u = normal.cross(helper).normalized();
  return {u, normal.cross(u)};
}

namespace {

// The edge (a, b) crosses the horizontal ray from q towards +x (crossing-number test).
bool CrossesRayRight(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& q) {
  return (a.y() > q.y()) != (b.y() > q.y()) &&
         q.x() < (b.x() - a.x()) * (q.y() - a.y()) / (b.y() - a.y()) + a.x();
}

// The segment (a, b) passes within sqrt(margin2) of q.
bool EdgeNear(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& q,
              double margin2) {
  const Eigen::Vector2d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((q - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (a + t * ab - q).squaredNorm() <= margin2;
}

}  // namespace

bool InsidePolygon2d(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& q) {
  bool inside = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    if (CrossesRayRight(ring[i], ring[j], q)) inside = !inside;
  }
  return inside;
}

bool InsideOrNearPolygon2d(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& q,
                           double margin) {
  if (InsidePolygon2d(ring, q)) return true;
  const double margin2 = margin * margin;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    if (EdgeNear(ring[i], ring[j], q, margin2)) return true;
  }
  return false;
}

IndexedPolygon2d::IndexedPolygon2d(std::vector<Eigen::Vector2d> ring) : ring_(std::move(ring)) {
  const int n = static_cast<int>(ring_.size());
  if (n < 3) return;
  double max_y = ring_[0].y();
  min_y_ = ring_[0].y();
  for (const Eigen::Vector2d& p : ring_) {
    min_y_ = std::min(min_y_, p.y());
    max_y = std::max(max_y, p.y());
  }
  // About one edge per slab on average; at least one slab.
  const int num_slabs = std::clamp(n, 1, 1024);
  slab_height_ = std::max((max_y - min_y_) / num_slabs, 1e-9);
  slab_edges_.assign(num_slabs, {});
  for (int e = 0; e < n; ++e) {
    const Eigen::Vector2d& a = ring_[e];
    const Eigen::Vector2d& b = ring_[e == 0 ? n - 1 : e - 1];
    const int first = std::clamp(Slab(std::min(a.y(), b.y())), 0, num_slabs - 1);
    const int last = std::clamp(Slab(std::max(a.y(), b.y())), 0, num_slabs - 1);
    for (int s = first; s <= last; ++s) slab_edges_[s].push_back(e);
  }
}

int IndexedPolygon2d::Slab(double y) const {
  // Clamped before the cast: a far query must not overflow int.
  const double outside = static_cast<double>(slab_edges_.size()) + 1.0;
  return static_cast<int>(std::clamp(std::floor((y - min_y_) / slab_height_), -2.0, outside));
}

bool IndexedPolygon2d::InsideOrNear(const Eigen::Vector2d& q, double margin) const {
  const int n = static_cast<int>(ring_.size());
  if (n < 3 || !q.allFinite()) return false;
  const int num_slabs = static_cast<int>(slab_edges_.size());
  auto edge = [&](int e) -> std::pair<const Eigen::Vector2d&, const Eigen::Vector2d&> {
    return {ring_[e], ring_[e == 0 ? n - 1 : e - 1]};
  };
  // Crossing number: an edge crosses the line y = q.y only if q.y lies in its y-range, and every
  // such edge is in q.y's slab (clamped: q.y at the top vertex belongs to the last slab).
  const int slab = Slab(q.y());
  if (slab >= -1 && slab <= num_slabs) {
    bool inside = false;
    for (const int e : slab_edges_[std::clamp(slab, 0, num_slabs - 1)]) {
      const auto [a, b] = edge(e);
      if (CrossesRayRight(a, b, q)) inside = !inside;
    }
    if (inside) return true;
  }
  const double margin2 = margin * margin;
  // Clamped at both ends: q exactly on the top vertex lies in slab num_slabs, whose edges the
  // constructor put into the last one.
  const int first = std::clamp(Slab(q.y() - margin), 0, num_slabs - 1);
  const int last = std::clamp(Slab(q.y() + margin), 0, num_slabs - 1);
  for (int s = first; s <= last; ++s) {
    for (const int e : slab_edges_[s]) {
      const auto [a, b] = edge(e);
      if (EdgeNear(a, b, q, margin2)) return true;
    }
  }
  return false;
}

}  // namespace planeloc
