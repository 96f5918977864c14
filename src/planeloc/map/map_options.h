// YAML options of `planeloc map planes` (--options FILE):
//
//   voxel_size:         -1   (metres; -1 = tensor_voting.sigma / 5, 0 = no voxel filter)
//   coarse_below_plane_fraction: 0.5  (vote again at 2 sigma below it; 0 = never)
//   tensor_voting:      {sigma: 0.5, radius_factor: 1.5, curvature_weight: 10,
//                        max_stick_angle_deg: 45, stick_passes: 2, max_neighbors: 512}
//   plane_extraction:   {min_stick_saliency: 0.5, growth_angle_deg: 15, ..., up: [0, -1, 0],
//                        detect_up: false (giving `up` sets it false),
//                        clustering: {max_clusters: 20, merge_angle_deg: 12, ...},
//                        outline: {cell_size: 0.25, closing_cells: 1, simplify_cells: 1}}
//
// Every key is optional (defaults from the structs). Unknown keys are warned about (and listed
// together); a value of the wrong type is an InputError naming the file and line. The effective
// options are written back into planes.json's stats by MapOptionsToJson.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "planeloc/map/plane_extraction.h"
#include "planeloc/map/tensor_voting.h"

namespace planeloc {

struct MapPlanesOptions {
  // Metres. The map is averaged per voxel of this side before tensor voting, so that a raw scan
  // (thousands of points a square metre near the sensor) costs what a voxelized map of the same
  // extent costs. < 0: tensor_voting.sigma / 5 (0.1 m by default, the `map build` voxel: a
  // neighbourhood of radius 1.5 sigma then holds ~180 points on a plane); 0: no filter.
  double voxel_size = -1.0;
  TensorVotingOptions tensor_voting;
  PlaneExtractionOptions plane_extraction;
  // Scale selection: when fewer than this fraction of the (voxel-filtered) points end up on
  // planes, the map is voted again at twice tensor_voting.sigma and the pass with more points on
  // planes is kept. A map registered from poses a few centimetres off (5 cm, 0.2 deg) has 25-32 %
  // on planes at 0.5 m and 54-57 % at 1 m; clean simulator maps 83-89 %. 0 = one scale only.
  double coarse_below_plane_fraction = 0.5;

  double EffectiveVoxelSize() const {
    return voxel_size < 0.0 ? tensor_voting.sigma / 5.0 : voxel_size;
  }
  void Check() const;  // throws OptionsError naming the field
};

// Overwrites the fields present in the file; returns the unknown keys (dotted paths), which it also
// logs as warnings. Throws InputError for a missing/unparsable file or a mistyped value.
std::vector<std::string> LoadMapPlanesOptions(const std::filesystem::path& path,
                                              MapPlanesOptions& options);

nlohmann::json MapOptionsToJson(const MapPlanesOptions& options);

}  // namespace planeloc
