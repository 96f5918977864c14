// Crease lines of a plane map: the 3-D lines where two fitted planes meet (a facade and the road,
// two facades at a corner), clipped to where both planes have support. Their position comes from
// the two plane equations (fitted to thousands of LiDAR points: centimetres), not from the
// planes' outlines (occupancy cells of the map, 0.25 m): they are what the image-side checks of
// the map (LSD segments at keyframes, crease_check.h) compare with.
//
// For each pair of planes whose normals are at least min_angle_deg apart and whose outlines
// (bounding boxes grown by support_margin) meet, the intersection line is sampled every
// sample_step metres; a sample is supported when it lies within support_margin of both outlines
// (an outline's ring runs through the centres of its boundary cells, about half a cell inside
// the surface, and the LiDAR rarely sees the last decimetres of a facade above the road). Runs
// of supported samples (gaps up to max_gap bridged) at least min_length long are creases.
// For each plane of a crease, the side its surface lies on: probes side_probe metres from the
// crease, in the plane and perpendicular to the crease, tested against the outline; a plane with
// surface on both sides (a road running past a free-standing wall) is not bounded by the crease.
// Deterministic: creases ordered by (plane_a, plane_b, position along the line).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "planeloc/io/plane_map.h"

namespace planeloc {

struct PlaneCreaseOptions {
  double min_angle_deg = 30.0;  // degrees between the normals, at least
  double support_margin = 0.5;  // metres from an outline still counted as its support
  double min_length = 1.0;      // metres, shortest crease kept
  double max_gap = 1.0;         // metres of unsupported line bridged inside a crease
  double sample_step = 0.05;    // metres between samples along the line
  double side_probe = 1.0;      // metres from the crease at which the planes' sides are probed
  double min_plane_area = 8.0;  // m^2: smaller planes are ignored (Planes.minPlaneArea)

  void Check() const;  // throws OptionsError naming the field
};

struct PlaneCrease {
  int id = 0;                                       // index in ComputePlaneCreases' result
  int plane_a = 0, plane_b = 0;                     // plane ids, plane_a < plane_b
  Eigen::Vector3d start = Eigen::Vector3d::Zero();  // map frame, on both planes
  Eigen::Vector3d end = Eigen::Vector3d::Zero();
  double angle_deg = 0;  // between the normals, in [min_angle_deg, 90]
  // Unit vector in plane a (b), perpendicular to the crease, pointing to the side where that
  // plane has its surface; zero when it has surface on both sides (the crease does not bound it).
  Eigen::Vector3d into_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d into_b = Eigen::Vector3d::Zero();
  double Length() const { return (end - start).norm(); }
};

// The creases of the planes with an outline (>= 3 vertices) and area >= min_plane_area (or
// unknown area, 0).
std::vector<PlaneCrease> ComputePlaneCreases(const PlaneMap& map,
                                             const PlaneCreaseOptions& options);

}  // namespace planeloc
