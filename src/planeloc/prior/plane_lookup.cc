#include "planeloc/prior/plane_lookup.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>
#include <utility>

namespace planeloc {
namespace {

constexpr std::int64_t kAxisCells = 1 << 20;  // per axis, centred on 0: +-5 000 km at 5 m

}  // namespace

PlaneLookup::PlaneLookup(const PlaneMap& planes, double min_plane_area, double cell_size,
                         double inflate)
    : cell_size_(cell_size) {
  for (const MapPlane& plane : planes.planes) {
    if (plane.area > 0.0 && plane.area < min_plane_area) continue;
    LookupPlane flat;
    flat.plane = plane;
    std::tie(flat.u, flat.v) = plane.plane_in_map.InPlaneBasis();
    const Eigen::Vector3d& up = planes.frame.up;
    flat.facade =
        plane.kind == "facade" || (plane.kind.empty() && !up.isZero() &&
                                   std::abs(plane.plane_in_map.normal.dot(up.normalized())) <
                                       std::sin(15.0 * std::numbers::pi / 180.0));
    const std::size_t index = planes_.size();
    index_by_id_[plane.id] = index;
    if (plane.polygon.size() < 3) {
      unbounded_.push_back(index);
      planes_.push_back(std::move(flat));
      continue;
    }
    Eigen::Vector3d lo = plane.polygon.front(), hi = plane.polygon.front();
    std::vector<Eigen::Vector2d> ring;
    for (const auto& p : plane.polygon) {
      ring.emplace_back(p.dot(flat.u), p.dot(flat.v));
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    flat.outline = IndexedPolygon2d(std::move(ring));
    lo.array() -= inflate;
    hi.array() += inflate;
    const Eigen::Array3d first = (lo / cell_size_).array().floor();
    const Eigen::Array3d last = (hi / cell_size_).array().floor();
    for (double x = first.x(); x <= last.x(); ++x) {
      for (double y = first.y(); y <= last.y(); ++y) {
        for (double z = first.z(); z <= last.z(); ++z) {
          cells_[CellKey(Eigen::Vector3d(x + 0.5, y + 0.5, z + 0.5) * cell_size_)].push_back(index);
        }
      }
    }
    planes_.push_back(std::move(flat));
  }
}

std::optional<std::size_t> PlaneLookup::IndexOf(int id) const {
  const auto it = index_by_id_.find(id);
  if (it == index_by_id_.end()) return std::nullopt;
  return it->second;
}

bool PlaneLookup::InsideOutline(std::size_t index, const Eigen::Vector3d& point,
                                double margin) const {
  const LookupPlane& flat = planes_[index];
  if (flat.outline.ring().size() < 3) return true;
  const Eigen::Vector2d q(point.dot(flat.u), point.dot(flat.v));
  return flat.outline.InsideOrNear(q, margin);
}

std::int64_t PlaneLookup::CellKey(const Eigen::Vector3d& point) const {
  const Eigen::Array3d c = (point / cell_size_).array().floor();
  auto axis = [](double value) {
    return std::clamp<std::int64_t>(static_cast<std::int64_t>(value) + kAxisCells / 2, 0,
                                    kAxisCells - 1);
  };
  return (axis(c.x()) * kAxisCells + axis(c.y())) * kAxisCells + axis(c.z());
}

}  // namespace planeloc
