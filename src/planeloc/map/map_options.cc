#include "planeloc/map/map_options.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <functional>
#include <map>
#include <regex>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// One settable field: reads a YAML scalar/sequence into the struct, writes it to JSON.
struct Field {
  std::function<void(const YAML::Node&)> read;
  std::function<nlohmann::json()> write;
};
using FieldTable = std::map<std::string, Field>;

template <typename T>
Field MakeField(T& value) {
  return {[&value](const YAML::Node& node) { value = node.as<T>(); },
          [&value]() { return nlohmann::json(value); }};
}

Field VectorField(Eigen::Vector3d& value) {
  return {[&value](const YAML::Node& node) {
            const auto v = node.as<std::vector<double>>();
            if (v.size() != 3) throw YAML::Exception(node.Mark(), "expected 3 numbers");
            value = Eigen::Vector3d(v[0], v[1], v[2]);
          },
          [&value]() {
            return nlohmann::json({value.x(), value.y(), value.z()});
          }};
}

// Giving `up` means the frame's up is known: it turns detection off (a later `detect_up: true`
// in the same file turns it back on).
Field UpField(PlaneExtractionOptions& options) {
  Field field = VectorField(options.up);
  auto read = field.read;
  field.read = [read, &options](const YAML::Node& node) {
    read(node);
    options.detect_up = false;
  };
  return field;
}

FieldTable Fields(MapPlanesOptions& o) {
  auto& tv = o.tensor_voting;
  auto& pe = o.plane_extraction;
  auto& cl = pe.clustering;
  return {
      {"voxel_size", MakeField(o.voxel_size)},
      {"coarse_below_plane_fraction", MakeField(o.coarse_below_plane_fraction)},
      {"tensor_voting.sigma", MakeField(tv.sigma)},
      {"tensor_voting.radius_factor", MakeField(tv.radius_factor)},
      {"tensor_voting.curvature_weight", MakeField(tv.curvature_weight)},
      {"tensor_voting.max_stick_angle_deg", MakeField(tv.max_stick_angle_deg)},
      {"tensor_voting.stick_passes", MakeField(tv.stick_passes)},
      {"tensor_voting.max_neighbors", MakeField(tv.max_neighbors)},
      {"plane_extraction.min_stick_saliency", MakeField(pe.min_stick_saliency)},
      {"plane_extraction.growth_angle_deg", MakeField(pe.growth_angle_deg)},
      {"plane_extraction.growth_distance", MakeField(pe.growth_distance)},
      {"plane_extraction.min_patch_points", MakeField(pe.min_patch_points)},
      {"plane_extraction.inlier_distance", MakeField(pe.inlier_distance)},
      {"plane_extraction.merge_angle_deg", MakeField(pe.merge_angle_deg)},
      {"plane_extraction.merge_distance", MakeField(pe.merge_distance)},
      {"plane_extraction.min_inliers", MakeField(pe.min_inliers)},
      {"plane_extraction.min_area", MakeField(pe.min_area)},
      {"plane_extraction.min_extent", MakeField(pe.min_extent)},
      {"plane_extraction.max_rms", MakeField(pe.max_rms)},
      {"plane_extraction.up", UpField(pe)},
      {"plane_extraction.detect_up", MakeField(pe.detect_up)},
      {"plane_extraction.kind_angle_deg", MakeField(pe.kind_angle_deg)},
      {"plane_extraction.outline.cell_size", MakeField(pe.outline.cell_size)},
      {"plane_extraction.outline.closing_cells", MakeField(pe.outline.closing_cells)},
      {"plane_extraction.outline.simplify_cells", MakeField(pe.outline.simplify_cells)},
      {"plane_extraction.outline.max_cells", MakeField(pe.outline.max_cells)},
      {"plane_extraction.clustering.max_clusters", MakeField(cl.max_clusters)},
      {"plane_extraction.clustering.merge_angle_deg", MakeField(cl.merge_angle_deg)},
      {"plane_extraction.clustering.iterations", MakeField(cl.iterations)},
      {"plane_extraction.clustering.max_seed_samples", MakeField(cl.max_seed_samples)},
  };
}

// A key read from the options file, with its value node (for its line).
struct ReadKey {
  std::string key;
  YAML::Node value;
};

void Visit(const YAML::Node& node, const std::string& prefix, const FieldTable& fields,
           const std::filesystem::path& path, std::vector<std::string>& unknown,
           std::vector<ReadKey>& read) {
  for (const auto& entry : node) {
    const std::string key = prefix + entry.first.as<std::string>();
    const auto it = fields.find(key);
    if (it != fields.end()) {
      try {
        it->second.read(entry.second);
        read.push_back({key, entry.second});
      } catch (const YAML::Exception&) {
        throw InputError(path.string(), entry.second.Mark().line + 1,
                         "option '" + key + "' has a value of the wrong type",
                         "give a number (or [x, y, z] for 'up')");
      }
    } else if (entry.second.IsMap()) {
      Visit(entry.second, key + ".", fields, path, unknown, read);
    } else {
      unknown.push_back(key);
    }
  }
}

}  // namespace

void MapPlanesOptions::Check() const {
  if (!std::isfinite(voxel_size)) throw OptionsError("MapPlanesOptions.voxel_size must be finite");
  if (!(coarse_below_plane_fraction >= 0.0 && coarse_below_plane_fraction <= 1.0)) {
    throw OptionsError("MapPlanesOptions.coarse_below_plane_fraction must be in [0, 1]");
  }
  tensor_voting.Check();
  plane_extraction.Check();
}

std::vector<std::string> LoadMapPlanesOptions(const std::filesystem::path& path,
                                              MapPlanesOptions& options) {
  CheckInput(std::filesystem::is_regular_file(path), path.string(), 0, "options file not found",
             "check the --options path");
  YAML::Node root;
  try {
    root = YAML::LoadFile(path.string());
  } catch (const YAML::Exception& e) {
    throw InputError(path.string(), e.mark.line + 1, "not valid YAML: " + e.msg,
                     "fix the YAML syntax");
  }
  std::vector<std::string> unknown;
  if (root.IsNull()) return unknown;  // an empty file: all defaults
  CheckInput(root.IsMap(), path.string(), 1, "the options file is not a YAML mapping",
             "write `tensor_voting:` and `plane_extraction:` sections");
  const MapPlanesOptions before = options;
  std::vector<ReadKey> read;
  Visit(root, "", Fields(options), path, unknown, read);
  try {
    options.Check();
  } catch (const OptionsError& error) {
    // Name the key and its line: the first key that alone, on the options given before the file,
    // makes them invalid (several keys together: the message names the field).
    for (const ReadKey& entry : read) {
      MapPlanesOptions alone = before;
      Fields(alone).at(entry.key).read(entry.value);
      try {
        alone.Check();
      } catch (const OptionsError& single) {
        throw InputError(
            path.string(), entry.value.Mark().line + 1,
            // "TensorVotingOptions.sigma must be > 0": the key is named, drop the struct's name.
            fmt::format("option '{}' = {}: {}", entry.key, YAML::Dump(entry.value),
                        std::regex_replace(single.what(), std::regex("[A-Za-z]+Options\\."), "")),
            "give the option a value in its range (docs/map.md), or remove it");
      }
    }
    throw InputError(path.string(), 0, fmt::format("invalid options: {}", error.what()),
                     "give the options values in their ranges (docs/map.md)");
  }
  for (const auto& key : unknown) {
    spdlog::warn("{}: unknown option '{}' ignored", path.string(), key);
  }
  return unknown;
}

nlohmann::json MapOptionsToJson(const MapPlanesOptions& options) {
  MapPlanesOptions copy = options;
  nlohmann::json json = nlohmann::json::object();
  for (const auto& [key, field] : Fields(copy)) json[key] = field.write();
  return json;
}

}  // namespace planeloc
