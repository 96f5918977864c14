// Which visual map points lie on a plane of the LiDAR prior (planes.json): the association that
// gives a point its point-to-plane residual in the window BA (the paper's points p on a plane vs
// points q off planes).
//
// A point is on plane k when it is within `max_distance` of the infinite plane AND its projection
// onto the plane lies inside the plane's outline grown by `polygon_margin` (the outline is where
// the LiDAR saw the surface: the infinite extension of a facade runs through the street behind it).
// A point within `max_distance` of two planes (a crease, a kerb) is not associated: the wrong
// choice would pull it across the crease, and the BA loses little by leaving it visual only.
// Planes are found through a coarse 3-D grid of their inflated bounding boxes, so a query costs a
// few polygon tests whatever the size of the map.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <unordered_map>
#include <vector>

#include "planeloc/io/plane_map.h"

namespace planeloc {

struct PlaneAssociationOptions {
  double max_distance = 0.15;   // metres from the plane (stereo depth noise + map noise)
  double polygon_margin = 0.5;  // metres outside the outline still accepted
  double min_plane_area = 8.0;  // m^2: smaller planes of the map are not used
  double cell_size = 5.0;       // metres, lookup grid

  void Check() const;  // throws OptionsError naming the field
};

class PlaneAssociator {
 public:
  // Keeps the planes with at least min_plane_area (all of them when their area is unknown, 0).
  PlaneAssociator(const PlaneMap& planes, const PlaneAssociationOptions& options);

  // The id of the plane `point_in_map` lies on, if exactly one.
  std::optional<int> Associate(const Eigen::Vector3d& point_in_map) const;
  // Plane by id (as in planes.json). Throws std::out_of_range for an unknown id.
  const MapPlane& plane(int id) const;
  std::size_t size() const { return planes_.size(); }

 private:
  struct FlatPlane {
    MapPlane plane;
    Eigen::Vector3d u, v;               // in-plane basis
    std::vector<Eigen::Vector2d> ring;  // outline in (u, v); empty: unbounded
  };
  bool InsideOutline(const FlatPlane& flat, const Eigen::Vector3d& point) const;
  std::int64_t CellKey(const Eigen::Vector3d& point) const;

  PlaneAssociationOptions options_;
  std::vector<FlatPlane> planes_;
  std::unordered_map<int, std::size_t> index_by_id_;
  std::unordered_map<std::int64_t, std::vector<std::size_t>> cells_;
  std::vector<std::size_t> unbounded_;  // planes without an outline: tested everywhere
};

}  // namespace planeloc
