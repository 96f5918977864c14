// Where the prior map's planes are: each plane with its in-plane basis and its outline, found
// through a coarse 3-D grid of their inflated bounding boxes, so a query costs a few polygon tests
// whatever the size of the map. The geometry under PlaneAssociator (plane_association.h): nothing
// here knows a point's uncertainty or a plane's health.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include "planeloc/geometry/plane.h"
#include "planeloc/io/plane_map.h"

namespace planeloc {

struct LookupPlane {
  MapPlane plane;
  Eigen::Vector3d u, v;      // in-plane basis
  IndexedPolygon2d outline;  // in (u, v); fewer than 3 vertices: unbounded
  bool facade = false;       // a witness of the trajectory's horizontal offset (consensus)
};

class PlaneLookup {
 public:
  // Keeps the planes with at least `min_plane_area` m^2 (all of them when their area is unknown,
  // 0), in the map's order. A plane is found from every cell of `cell_size` metres that its
  // bounding box grown by `inflate` metres touches; a plane without an outline from everywhere.
  PlaneLookup(const PlaneMap& planes, double min_plane_area, double cell_size, double inflate);

  std::size_t size() const { return planes_.size(); }
  const LookupPlane& operator[](std::size_t index) const { return planes_[index]; }
  // The index of the plane with map id `id`, if kept.
  std::optional<std::size_t> IndexOf(int id) const;
  // Whether the point's projection onto the plane lies inside its outline grown by `margin`
  // metres (always true for a plane without an outline).
  bool InsideOutline(std::size_t index, const Eigen::Vector3d& point, double margin) const;
  // Calls f(index) for the planes whose cells contain the point (unbounded planes first); stops
  // when f returns false.
  template <typename F>
  void ForCandidates(const Eigen::Vector3d& point, F f) const;

 private:
  std::int64_t CellKey(const Eigen::Vector3d& point) const;

  double cell_size_;
  std::vector<LookupPlane> planes_;
  std::unordered_map<int, std::size_t> index_by_id_;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> cells_;
  std::vector<std::size_t> unbounded_;  // planes without an outline: tested everywhere
};

template <typename F>
void PlaneLookup::ForCandidates(const Eigen::Vector3d& point, F f) const {
  for (const std::size_t index : unbounded_) {
    if (!f(index)) return;
  }
  const auto cell = cells_.find(CellKey(point));
  if (cell == cells_.end()) return;
  for (const std::size_t index : cell->second) {
    if (!f(index)) return;
  }
}

}  // namespace planeloc
