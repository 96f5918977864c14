#include "planeloc/geometry/plane.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <stdexcept>

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

bool InsidePolygon2d(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& q) {
  bool inside = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Eigen::Vector2d& a = ring[i];
    const Eigen::Vector2d& b = ring[j];
    if ((a.y() > q.y()) != (b.y() > q.y()) &&
        q.x() < (b.x() - a.x()) * (q.y() - a.y()) / (b.y() - a.y()) + a.x()) {
      inside = !inside;
    }
  }
  return inside;
}

bool InsideOrNearPolygon2d(const std::vector<Eigen::Vector2d>& ring, const Eigen::Vector2d& q,
                           double margin) {
  if (InsidePolygon2d(ring, q)) return true;
  const double margin2 = margin * margin;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Eigen::Vector2d ab = ring[j] - ring[i];
    const double length2 = ab.squaredNorm();
    const double t = length2 > 0.0 ? std::clamp((q - ring[i]).dot(ab) / length2, 0.0, 1.0) : 0.0;
    if ((ring[i] + t * ab - q).squaredNorm() <= margin2) return true;
  }
  return false;
}

}  // namespace planeloc
