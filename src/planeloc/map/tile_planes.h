// Plane extraction on one tile of a tiled map (map_tiles.h; issue 15), and what a tile hands to
// the merge (plane_merge.h): the tile's planes cut to its core, small enough to gather from MPI
// ranks (a few kB per plane).
//
// The tile (core + overlap band) goes through RunMapPlanes as an untiled map would, so tensor
// voting near a border sees the neighbours' points. Each extracted plane then becomes a
// TilePiece: its description as extracted (kept verbatim when every inlier lies in the core), and
// its core inliers summarized by their count, mean and scatter (the total-least-squares fit of a
// union of pieces needs nothing else) and by one sample per occupied outline cell (for the
// outline of a merged plane); its inliers in the overlap band by one sample per cell too (for the
// test across a border: the band is the neighbours' core, seen by both tiles).
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/io/plane_map.h"
#include "planeloc/io/point_cloud.h"
#include "planeloc/map/map_options.h"
#include "planeloc/map/map_tiles.h"
#include "planeloc/map/plane_map_eval.h"

namespace planeloc {

struct TilePiece {
  MapPlane plane;         // as extracted in the tile (its id = the tile's plane id)
  bool complete = false;  // every inlier lies in the tile's core
  std::size_t core_inliers = 0;
  Eigen::Vector3d core_mean = Eigen::Vector3d::Zero();     // map frame, metres
  Eigen::Matrix3d core_scatter = Eigen::Matrix3d::Zero();  // sum (x - mean)(x - mean)^T, m^2
  std::vector<Eigen::Vector3d> samples;  // core inliers averaged per outline cell (map frame)
  // The inliers outside the core (in the overlap band, the neighbours' cores) averaged per
  // outline cell: where this piece continues into a neighbour, the cells it shares with the
  // neighbour's piece there (the merge's evidence that the two are one plane cut by the border).
  std::vector<Eigen::Vector3d> band_samples;
};

struct TilePlanes {
  TileKey key = {0, 0};
  std::string file;             // the tile's file, for messages
  std::string error;            // non-empty: the tile failed (the message); nothing else is valid
  std::size_t points = 0;       // after the voxel filter
  std::size_t core_points = 0;  // of which in the core
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  bool up_detected = false;
  double seconds = 0.0;             // wall-clock, for logs only
  std::vector<TilePiece> pieces;    // planes with at least one core inlier, by tile plane id
  std::optional<PlaneMapTally> gt;  // of the core points, labels = tile plane ids

  nlohmann::json ToJson() const;
  static TilePlanes FromJson(const nlohmann::json& json);
};

// Runs RunMapPlanes on `tile` (the tile file's points) and cuts the result to the core of `key`.
// With `gt`, also tallies the core points against it (eval_options.point_area must be set).
// Throws what RunMapPlanes throws.
TilePlanes ExtractTilePlanes(const PointCloud& tile, const TileKey& key, const TileGrid& grid,
                             const MapPlanesOptions& options, const PlaneMap* gt,
                             const PlaneMapEvalOptions& eval_options);

}  // namespace planeloc
