#include "planeloc/map/map_planes.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <new>
#include <string>

#include "planeloc/io/voxel_filter.h"
#include "planeloc/map/map_builder.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

double SecondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// HSV (h in [0, 1)) with full saturation and value 0.95 to RGB.
Eigen::Vector3d Hue(double h) {
  const double v = 0.95, s = 0.85;
  const double sector = h * 6.0;
  const int i = static_cast<int>(sector) % 6;
  const double f = sector - std::floor(sector);
  const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  switch (i) {
    case 0:
      return {v, t, p};
    case 1:
      return {q, v, p};
    case 2:
      return {p, v, t};
    case 3:
      return {p, q, v};
    case 4:
      return {t, p, v};
    default:
      return {v, p, q};
  }
}

// One pass at the options' scale: voxel filter, tensor voting, plane extraction.
MapPlanesOutput RunOneScale(const PointCloud& map, const MapPlanesOptions& options) {
  MapPlanesOutput output;
  output.voxel_size = options.EffectiveVoxelSize();
  try {
    auto start = std::chrono::steady_clock::now();
    if (output.voxel_size > 0.0) {
      output.points = VoxelFilter(map, output.voxel_size).points;
    } else {
      output.points = map.points;
    }
    output.voting = RunTensorVoting(output.points, options.tensor_voting);
    output.voting_seconds = SecondsSince(start);
    start = std::chrono::steady_clock::now();
    output.extraction = ExtractPlanes(output.points, output.voting, options.plane_extraction);
    output.extraction_seconds = SecondsSince(start);
  } catch (const std::bad_alloc&) {
    throw InputError("", 0,
                     fmt::format("map too large for memory ({} points, voxel {} m)", map.size(),
                                 output.voxel_size),
                     "use --voxel with a larger voxel, e.g. --voxel 0.2 (or crop the map)");
  }
  return output;
}

}  // namespace

double PlanePointFraction(const MapPlanesOutput& output) {
  if (output.points.empty()) return 0.0;
  const auto& labels = output.extraction.point_plane;
  const auto on_plane = std::count_if(labels.begin(), labels.end(), [](int l) { return l >= 0; });
  return static_cast<double>(on_plane) / static_cast<double>(output.points.size());
}

MapPlanesOutput RunMapPlanes(const PointCloud& map, const MapPlanesOptions& options) {
  options.Check();
  CheckInput(!map.empty(), "", 0, "the map is empty", "give a map with points");
  MapPlanesOutput output = RunOneScale(map, options);
  MapPlanesOptions effective = options;
  const double fine_fraction = PlanePointFraction(output);
  nlohmann::json scale = {{"sigma", options.tensor_voting.sigma},
                          {"plane_point_fraction", fine_fraction}};
  if (fine_fraction < options.coarse_below_plane_fraction) {
    // A map blurred beyond the voting scale (registered from poses a few centimetres off: each
    // pass a layer of its own) is not a surface at that scale. Vote again at twice the scale
    // (and, when the voxel follows the scale, twice the voxel) and keep the pass on which more
    // of the map lies on planes by a clear margin (a real scan's clutter, trees and cars, keeps
    // the fraction low at any scale: KITTI-00 scans 20-33 % at 0.5 m, 16-33 % at 1 m; a map from
    // noisy poses goes from 25-32 % to 54-57 %); docs/map.md, "Scale".
    MapPlanesOptions coarse = options;
    coarse.tensor_voting.sigma *= 2.0;
    MapPlanesOutput coarse_output = RunOneScale(map, coarse);
    const double coarse_fraction = PlanePointFraction(coarse_output);
    constexpr double kClearGain = 1.2;
    const bool keep_coarse = coarse_fraction >= kClearGain * fine_fraction;
    scale["coarse"] = {{"sigma", coarse.tensor_voting.sigma},
                       {"plane_point_fraction", coarse_fraction}};
    spdlog::info(
        "map planes: {:.0f} % of the points on planes at sigma {} m (below {:.0f} %: blurred "
        "surfaces); at sigma {} m: {:.0f} %; keeping sigma {} m",
        100.0 * fine_fraction, options.tensor_voting.sigma,
        100.0 * options.coarse_below_plane_fraction, coarse.tensor_voting.sigma,
        100.0 * coarse_fraction,
        keep_coarse ? coarse.tensor_voting.sigma : options.tensor_voting.sigma);
    if (keep_coarse) {
      coarse_output.voting_seconds += output.voting_seconds;
      coarse_output.extraction_seconds += output.extraction_seconds;
      output = std::move(coarse_output);
      effective = coarse;
    } else {
      output.voting_seconds += coarse_output.voting_seconds;
      output.extraction_seconds += coarse_output.extraction_seconds;
    }
  }
  nlohmann::json& stats = output.extraction.plane_map.stats;
  // The options of the pass kept: planes.json is reproducible from them.
  stats["options"] = MapOptionsToJson(effective);
  stats["scale"] = scale;
  // Points of the file when the map was voxel-filtered while reading (ReadPointCloud).
  stats["input_points"] = map.source_points > 0 ? map.source_points : map.size();
  // What `map build` read and dropped, carried from the map file's header.
  if (const auto counts = MapBuildCountsFromComments(map.comments)) stats["map_build"] = *counts;
  stats["voxel_size"] = output.voxel_size;
  return output;
}

void RequirePlanarStructure(const PlaneMap& planes, const std::string& map_path, std::size_t points,
                            const MapPlanesOptions& options) {
  if (!planes.planes.empty()) return;
  const PlaneExtractionOptions& extraction = options.plane_extraction;
  throw InputError(
      map_path, 0,
      fmt::format("no planar structure in {} points: no plane of at least {} inliers, {} m^2 and "
                  "{} m across within {} m (the map has no surfaces, or is not in metres)",
                  points, extraction.min_inliers, extraction.min_area, extraction.min_extent,
                  extraction.inlier_distance),
      "give a LiDAR map in metres that holds roads or walls; for a small or sparse map, lower "
      "--sigma and --voxel (docs/map.md, \"Options file\")");
}

std::vector<Eigen::Vector3d> PlaneColors(const MapPlanesOutput& output) {
  const auto& labels = output.extraction.point_plane;
  std::vector<Eigen::Vector3d> colors(labels.size());
  constexpr double kGolden = 0.618033988749895;  // spreads consecutive ids around the hue circle
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] >= 0) {
      colors[i] = Hue(std::fmod(0.1 + kGolden * labels[i], 1.0));
      continue;
    }
    switch (output.voting.classes[i]) {
      case SaliencyClass::kSurface:
        colors[i] = {0.7, 0.7, 0.7};
        break;
      case SaliencyClass::kCurve:
        colors[i] = {0.2, 0.3, 0.8};
        break;
      case SaliencyClass::kJunction:
        colors[i] = {0.45, 0.05, 0.05};
        break;
    }
  }
  return colors;
}

}  // namespace planeloc
