// `planeloc map tile`, `map build --tiles-out` and `map planes --tiles` (issue 15): the tiled map
// commands, wired from cmd_map.cc. The algorithms live in src/planeloc/map (map_tiles.h,
// tile_planes.h, plane_merge.h); MPI in mpi_world.h. See docs/map.md "Tiled maps".
#pragma once

#include <string>

#include "planeloc/map/map_builder.h"
#include "planeloc/map/map_options.h"
#include "planeloc/map/map_tiles.h"

namespace planeloc::cli {

struct TileArgs {
  std::string map;       // a map file, or:
  std::string sequence;  // a KITTI sequence and its poses, streamed scan by scan
  std::string poses;
  std::string out;  // the tiles folder (created)
  TilingOptions tiling;
  MapBuildOptions build;
};

int RunTile(const TileArgs& args);

struct TiledPlanesArgs {
  std::string tiles;  // the tiles folder
  std::string out;
  std::string gt;
  std::string frame;
  double gt_min_area = 20.0;  // m^2 a GT plane must show in the map to be checked
  bool gt_all_kinds = false;  // also check "other" GT planes (ceilings, table tops)
};

// `options` checked; runs the tiles one after another, or spread over MPI ranks when launched by
// mpirun / srun (rank 0 merges and writes).
int RunTiledPlanes(const TiledPlanesArgs& args, const MapPlanesOptions& options);

}  // namespace planeloc::cli
