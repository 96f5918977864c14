// How well a LiDAR map knows each of its planes (issue 32; docs/map.md, "Plane uncertainty").
//
// An accumulated map has two kinds of error on a plane. The range noise of each return is white:
// it averages out over the inliers (rms / sqrt(N)). The registration error of the scans is not: a
// scan placed a few centimetres off shifts every point it contributed, and a map built from
// drifting poses bends a long road or facade. That part shows in the map itself as structure at
// the scale of metres: the mean residual of the inliers in each 1 m cell of the plane varies from
// cell to cell far more than white noise allows. The sigma below adds both, each scaled by the
// plane's extent for the normal. The map has no viewpoints (an accumulated .pcd), so range and
// incidence enter only through the residuals they cause.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "planeloc/geometry/plane.h"
#include "planeloc/io/plane_map.h"

namespace planeloc {

// What the inliers of one plane show about its error.
struct PlaneSpread {
  int points = 0;
  double rms = 0;  // metres: the inliers' residuals about the plane
  Eigen::Vector3d major_axis = Eigen::Vector3d::Zero();  // unit, in the plane, longest direction
  // Along (minor, major): standard deviation of the inliers' in-plane coordinates, and the extent
  // (max - min), metres.
  Eigen::Vector2d deviation = Eigen::Vector2d::Zero();
  Eigen::Vector2d extent = Eigen::Vector2d::Zero();
  int cells = 0;  // cells of cell_size with at least kMinCellPoints inliers
  // Metres: rms over those cells of their mean residual, less the part the white noise of their
  // members explains.
  double cell_spread = 0;
};

constexpr double kPlaneSpreadCellSize = 1.0;  // metres
constexpr int kMinCellPoints = 5;             // inliers a cell needs to count

// `plane` is the fitted plane of `inliers` (indices into points); needs >= 3 of them.
PlaneSpread MeasurePlaneSpread(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<int>& inliers, const Plane& plane);

// The same for a plane known by its point count, rms and samples that each average the inliers
// of a small cell (the merge across tiles, tile_planes.h): a cell needs one sample to count.
PlaneSpread MeasureSampledPlaneSpread(const std::vector<Eigen::Vector3d>& samples, int points,
                                      double rms, const Plane& plane);

// The sigma of the plane's offset at its centroid and of its normal (PlaneSigma), from its spread.
PlaneSigma PlaneSigmaFromSpread(const PlaneSpread& spread);

}  // namespace planeloc
