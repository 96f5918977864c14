// The merge of a tiled `map planes` run (issue 15): the tiles' pieces (tile_planes.h) become one
// plane map, as if the map had been processed whole.
//
//  1. up: the given one, or (detect_up) the up detected by most core points over the tiles;
//  2. pieces join (union-find) only where a tile border cut a plane: a piece of one tile
//     continues into the overlap band (the neighbour's core), and the neighbour's piece holds
//     core inliers in the same outline cells (the same points, extracted by both tiles); the two
//     lie on the same plane by the untiled patch-merge test (normals within merge_angle_deg, each
//     core centroid within merge_distance of the other's plane); and the group's joint fit holds
//     every member within the untiled robust fit's consensus band (normals within
//     merge_angle_deg, core centroids within inlier_distance / 2). Two pieces of one tile are not
//     joined directly: the tile's extraction kept them apart by the untiled rules;
//  3. a piece alone and complete (all its inliers in its core) is kept as the tile extracted it;
//     any other group is refitted from its pieces' core moments (total least squares), outlined
//     from their samples (plane_outline.h) and checked against the extraction's min_inliers,
//     max_rms, min_extent and min_area;
//  4. normals are oriented and kinds set with the global up; planes sorted by inliers (ties in
//     tile-key order), ids 0..n-1.
// Depends only on the tiles' results in key order: the same output for any number of MPI ranks.
#pragma once

#include <map>
#include <utility>
#include <vector>

#include "planeloc/io/plane_map.h"
#include "planeloc/map/map_options.h"
#include "planeloc/map/map_tiles.h"
#include "planeloc/map/tile_planes.h"

namespace planeloc {

struct MergedPlanes {
  PlaneMap plane_map;  // stats: tiles, pieces, joined_groups, planes, points, ...
  Eigen::Vector3d up = Eigen::Vector3d::Zero();
  bool up_detected = false;
  // (index in `tiles`, tile plane id) -> id in plane_map, for the pieces that made it.
  std::map<std::pair<int, int>, int> piece_ids;
};

// `tiles` sorted by key, none failed. Throws std::invalid_argument otherwise.
MergedPlanes MergeTilePlanes(const std::vector<TilePlanes>& tiles, const MapPlanesOptions& options);

// Sums the tiles' GT tallies with their plane ids replaced by the merged ids.
PlaneMapTally MergeTileTallies(const std::vector<TilePlanes>& tiles, const MergedPlanes& merged);

}  // namespace planeloc
