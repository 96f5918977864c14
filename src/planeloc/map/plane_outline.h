// Concave outline of a planar patch: the patch's inliers, in 2-D plane coordinates, are
// rasterized into an occupancy grid, small gaps (scan-line spacing, missing voxels) are closed by a
// morphological closing, and the outer boundary of the largest 8-connected component is traced and
// simplified. Unlike a convex hull this follows L-shaped facades, facades with gaps and ground
// planes along a turning road.
//
// Choices (see docs/map.md):
//  - the polygon is ONE ring (planes.json has one ring per plane): the outer boundary of the
//    largest connected component, holes are not represented in it;
//  - `area` is the occupied-cell area of ALL components after closing, each boundary cell
//    counted 1 - 0.5 per empty 4-neighbour, at least 1/4 (holes wider than ~2 closing
//    radii and the gaps between disjoint pieces are not counted), so it measures the observed
//    surface, not the ring's area;
//  - ring vertices are cell centres of boundary cells, so each vertex lies within one cell of an
//    input point and the ring lies inside the observed surface (it is ~half a cell smaller than
//    the occupied area on each side).
// Deterministic (no randomness; depends only on the input order-independent cell occupancy).
#pragma once

#include <Eigen/Core>
#include <vector>

namespace planeloc {

struct PlaneOutlineOptions {
  // Metres, edge of an occupancy cell: ~2x the map voxel / point spacing (0.10 m voxel map).
  double cell_size = 0.25;
  // Radius (cells) of the square closing element: closes gaps up to 2 * closing_cells cells wide.
  int closing_cells = 1;
  // Douglas-Peucker tolerance of the ring simplification, in cells.
  double simplify_cells = 1.0;
  // A grid larger than this many cells gets a proportionally larger cell (memory bound).
  double max_cells = 2.5e7;

  void Check() const;  // throws OptionsError naming the field
};

struct PlaneOutline2d {
  std::vector<Eigen::Vector2d> ring;  // counter-clockwise, plane coordinates; empty if no points
  double area = 0.0;                  // m^2, occupied-cell area after closing, edge-corrected
  double cell_size = 0.0;             // metres, the cell size actually used
};

// Outline of 2-D points (plane coordinates, metres).
PlaneOutline2d ComputePlaneOutline2d(const std::vector<Eigen::Vector2d>& points,
                                     const PlaneOutlineOptions& options);

}  // namespace planeloc
