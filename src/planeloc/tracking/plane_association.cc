#include "planeloc/tracking/plane_association.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// Squared distance from q to the segment [a, b].
double SegmentDistance2(const Eigen::Vector2d& q, const Eigen::Vector2d& a,
                        const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((q - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (a + t * ab - q).squaredNorm();
}

constexpr std::int64_t kAxisCells = 1 << 20;  // per axis, centred on 0: +-5 000 km at 5 m

}  // namespace

void PlaneAssociationOptions::Check() const {
  if (!(max_distance > 0.0)) {
    throw OptionsError("PlaneAssociationOptions.max_distance must be > 0 (m)");
  }
  if (!(polygon_margin >= 0.0)) {
    throw OptionsError("PlaneAssociationOptions.polygon_margin must be >= 0 (m)");
  }
  if (!(min_plane_area >= 0.0)) {
    throw OptionsError("PlaneAssociationOptions.min_plane_area must be >= 0 (m^2)");
  }
  if (!(cell_size > 0.0)) throw OptionsError("PlaneAssociationOptions.cell_size must be > 0 (m)");
}

PlaneAssociator::PlaneAssociator(const PlaneMap& planes, const PlaneAssociationOptions& options)
    : options_(options) {
  options_.Check();
  const double inflate = options_.polygon_margin + options_.max_distance;
  for (const MapPlane& plane : planes.planes) {
    if (plane.area > 0.0 && plane.area < options_.min_plane_area) continue;
    FlatPlane flat;
    flat.plane = plane;
    std::tie(flat.u, flat.v) = plane.plane_in_map.InPlaneBasis();
    const std::size_t index = planes_.size();
    index_by_id_[plane.id] = index;
    if (plane.polygon.size() < 3) {
      unbounded_.push_back(index);
      planes_.push_back(std::move(flat));
      continue;
    }
    Eigen::Vector3d lo = plane.polygon.front(), hi = plane.polygon.front();
    for (const auto& p : plane.polygon) {
      flat.ring.emplace_back(p.dot(flat.u), p.dot(flat.v));
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    lo.array() -= inflate;
    hi.array() += inflate;
    const Eigen::Array3d first = (lo / options_.cell_size).array().floor();
    const Eigen::Array3d last = (hi / options_.cell_size).array().floor();
    for (double x = first.x(); x <= last.x(); ++x) {
      for (double y = first.y(); y <= last.y(); ++y) {
        for (double z = first.z(); z <= last.z(); ++z) {
          cells_[CellKey(Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5) * options_.cell_size)]
              .push_back(index);
        }
      }
    }
    planes_.push_back(std::move(flat));
  }
}

std::int64_t PlaneAssociator::CellKey(const Eigen::Vector3d& point) const {
  const Eigen::Array3d c = (point / options_.cell_size).array().floor();
  auto axis = [](double value) {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>(value) + kAxisCells / 2, 0,
                                    kAxisCells - 1);
  };
  return (axis(c.x()) * kAxisCells + axis(c.y())) * kAxisCells + axis(c.z());
}

bool PlaneAssociator::InsideOutline(const FlatPlane& flat, const Eigen::Vector3d& point) const {
  if (flat.ring.size() < 3) return true;
  const Eigen::Vector2d q(point.dot(flat.u), point.dot(flat.v));
  if (InsidePolygon2d(flat.ring, q)) return true;
  double nearest2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0, j = flat.ring.size() - 1; i < flat.ring.size(); j = i++) {
    nearest2 = std::min(nearest2, SegmentDistance2(q, flat.ring[i], flat.ring[j]));
  }
  return nearest2 <= options_.polygon_margin * options_.polygon_margin;
}

std::optional<int> PlaneAssociator::Associate(const Eigen::Vector3d& point_in_map) const {
  if (!point_in_map.allFinite()) return std::nullopt;
  std::optional<int> found;
  auto test = [&](std::size_t index) {
    const FlatPlane& flat = planes_[index];
    if (std::abs(flat.plane.plane_in_map.SignedDistance(point_in_map)) > options_.max_distance) {
      return true;
    }
    if (!InsideOutline(flat, point_in_map)) return true;
    if (found && *found != flat.plane.id) {
      found.reset();
      return false;  // ambiguous: two planes claim the point
    }
    found = flat.plane.id;
    return true;
  };
  for (const std::size_t index : unbounded_) {
    if (!test(index)) return std::nullopt;
  }
  const auto cell = cells_.find(CellKey(point_in_map));
  if (cell != cells_.end()) {
    for (const std::size_t index : cell->second) {
      if (!test(index)) return std::nullopt;
    }
  }
  return found;
}

const MapPlane& PlaneAssociator::plane(int id) const {
  const auto it = index_by_id_.find(id);
  if (it == index_by_id_.end()) {
    throw std::out_of_range("PlaneAssociator: no plane with id " + std::to_string(id));
  }
  return planes_[it->second].plane;
}

}  // namespace planeloc
