// The whole `planeloc map planes` computation on a loaded map, without any file handling:
// tensor voting, plane extraction, the effective options in the stats, and viewing colours.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "planeloc/io/point_cloud.h"
#include "planeloc/map/map_options.h"
#include "planeloc/map/plane_extraction.h"
#include "planeloc/map/tensor_voting.h"

namespace planeloc {

struct MapPlanesOutput {
  // The points voted on and labelled: the input map voxel-filtered (options.voxel_size), in
  // voxel order; `voting` and `extraction.point_plane` index these.
  std::vector<Eigen::Vector3d> points;
  double voxel_size = 0.0;  // metres, effective (0: the input points as given)
  TensorVotingResult voting;
  PlaneExtractionResult extraction;  // plane_map.stats also holds "options"
  double voting_seconds = 0.0;       // wall-clock, for logs only (not written to planes.json)
  double extraction_seconds = 0.0;
};

// Fraction of output.points on a plane (extraction.point_plane >= 0); 0 for no points.
double PlanePointFraction(const MapPlanesOutput& output);

// Voxel filter, tensor voting and plane extraction (up detected when
// options.plane_extraction.detect_up). Throws OptionsError for bad options, InputError for an
// empty map and InputError("map too large for memory: use --voxel") when the neighbourhoods do not
// fit. A map (or a tile) without planes gives an empty plane map.
MapPlanesOutput RunMapPlanes(const PointCloud& map, const MapPlanesOptions& options);

// A whole map must hold at least one plane: throws InputError naming `map_path` (the file or the
// tiles folder) when `planes` is empty, with what usually causes it (units, a map of vegetation).
void RequirePlanarStructure(const PlaneMap& planes, const std::string& map_path, std::size_t points,
                            const MapPlanesOptions& options);

// One RGB colour per point for viewing: plane points by plane id (distinct hues), the others by
// tensor-voting class (surface light grey, curve blue, junction dark red).
std::vector<Eigen::Vector3d> PlaneColors(const MapPlanesOutput& output);

}  // namespace planeloc
