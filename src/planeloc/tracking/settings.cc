#include "planeloc/tracking/settings.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <sstream>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

void Require(bool condition, const std::string& what) {
  if (!condition) throw OptionsError("TrackerOptions: " + what);
}

// One settings key bound to a field of TrackerOptions.
struct Key {
  std::string name;
  enum Kind { kInt, kDouble, kBool } kind;
  std::function<double&(TrackerOptions&)> real;  // kDouble
  std::function<int&(TrackerOptions&)> integer;  // kInt
  std::function<bool&(TrackerOptions&)> flag;    // kBool
};

Key D(std::string name, std::function<double&(TrackerOptions&)> f) {
  return {std::move(name), Key::kDouble, std::move(f), {}, {}};
}
Key I(std::string name, std::function<int&(TrackerOptions&)> f) {
  return {std::move(name), Key::kInt, {}, std::move(f), {}};
}
Key B(std::string name, std::function<bool&(TrackerOptions&)> f) {
  return {std::move(name), Key::kBool, {}, {}, std::move(f)};
}

const std::vector<Key>& Keys() {
  using O = TrackerOptions;
  static const std::vector<Key> keys = {
      // ORB-SLAM2 names.
      D("Camera.fps", [](O& o) -> double& { return o.fps; }),
      D("ThDepth", [](O& o) -> double& { return o.close_depth_baselines; }),
      I("ORBextractor.nFeatures", [](O& o) -> int& { return o.orb.num_features; }),
      D("ORBextractor.scaleFactor", [](O& o) -> double& { return o.orb.scale_factor; }),
      I("ORBextractor.nLevels", [](O& o) -> int& { return o.orb.num_levels; }),
      I("ORBextractor.iniThFAST", [](O& o) -> int& { return o.orb.initial_fast_threshold; }),
      I("ORBextractor.minThFAST", [](O& o) -> int& { return o.orb.min_fast_threshold; }),
      // planeloc's own.
      I("Stereo.maxDescriptorDistance",
        [](O& o) -> int& { return o.stereo.max_descriptor_distance; }),
      I("Stereo.sadWindowHalfSize", [](O& o) -> int& { return o.stereo.sad_window_half_size; }),
      I("Stereo.sadSearchHalfRange", [](O& o) -> int& { return o.stereo.sad_search_half_range; }),
      D("Stereo.minDepth", [](O& o) -> double& { return o.stereo.min_depth; }),
      I("PoseOptimizer.rounds", [](O& o) -> int& { return o.pose.rounds; }),
      I("PoseOptimizer.iterationsPerRound",
        [](O& o) -> int& { return o.pose.iterations_per_round; }),
      D("Tracking.motionSearchRadius", [](O& o) -> double& { return o.motion_search_radius; }),
      I("Tracking.minMotionMatches", [](O& o) -> int& { return o.min_motion_matches; }),
      I("Tracking.minTrackedInliers", [](O& o) -> int& { return o.min_tracked_inliers; }),
      I("Tracking.maxLocalKeyframes", [](O& o) -> int& { return o.max_local_keyframes; }),
      D("Tracking.localSearchRadius", [](O& o) -> double& { return o.local_search_radius; }),
      D("Tracking.keyframeTrackedRatio", [](O& o) -> double& { return o.keyframe_tracked_ratio; }),
      I("Tracking.keyframeMinCloseTracked",
        [](O& o) -> int& { return o.keyframe_min_close_tracked; }),
      I("Tracking.keyframeMinCloseUntracked",
        [](O& o) -> int& { return o.keyframe_min_close_untracked; }),
      I("Mapping.minNewStereoPoints", [](O& o) -> int& { return o.min_new_stereo_points; }),
      D("Mapping.farDepthBaselines", [](O& o) -> double& { return o.far_depth_baselines; }),
      B("Mapping.triangulateWithNeighbours",
        [](O& o) -> bool& { return o.triangulate_with_neighbours; }),
      I("Mapping.triangulationNeighbours", [](O& o) -> int& { return o.triangulation_neighbours; }),
      D("Mapping.minFoundRatio", [](O& o) -> double& { return o.min_found_ratio; }),
      I("Mapping.minPointObservations", [](O& o) -> int& { return o.min_point_observations; }),
      I("LocalBA.windowKeyframes", [](O& o) -> int& { return o.ba_window_keyframes; }),
      I("LocalBA.maxFixedKeyframes", [](O& o) -> int& { return o.ba_max_fixed_keyframes; }),
      I("LocalBA.iterations", [](O& o) -> int& { return o.ba.iterations; }),
      D("LocalBA.lambda", [](O& o) -> double& { return o.ba.lambda; }),
      D("LocalBA.planeSigma", [](O& o) -> double& { return o.ba.plane_sigma; }),
      D("LocalBA.planeHuber", [](O& o) -> double& { return o.ba.plane_huber; }),
      D("LocalBA.planeOutlierDistance",
        [](O& o) -> double& { return o.ba.plane_outlier_distance; }),
      I("LocalBA.windowKeyframesTurn", [](O& o) -> int& { return o.ba_window_keyframes_turn; }),
      D("LocalBA.turnAngleDeg", [](O& o) -> double& { return o.ba_turn_angle_deg; }),
      D("Planes.maxDistance", [](O& o) -> double& { return o.planes.max_distance; }),
      D("Planes.polygonMargin", [](O& o) -> double& { return o.planes.polygon_margin; }),
      D("Planes.minPlaneArea", [](O& o) -> double& { return o.planes.min_plane_area; }),
      D("Planes.gateChi2", [](O& o) -> double& { return o.planes.gate_chi2; }),
      D("Planes.mapSigma", [](O& o) -> double& { return o.planes.map_sigma; }),
      D("Planes.pixelSigma", [](O& o) -> double& { return o.planes.pixel_sigma; }),
      I("Planes.minAssociations", [](O& o) -> int& { return o.planes.min_associations; }),
      D("Planes.statsBand", [](O& o) -> double& { return o.planes.stats_band; }),
      D("Planes.statsMaxPointSigma",
        [](O& o) -> double& { return o.planes.stats_max_point_sigma; }),
      D("Planes.biasMin", [](O& o) -> double& { return o.planes.bias_min; }),
      D("Planes.biasSignificance", [](O& o) -> double& { return o.planes.bias_significance; }),
      I("Planes.biasMinPoints", [](O& o) -> int& { return o.planes.bias_min_points; }),
      B("System.deterministic", [](O& o) -> bool& { return o.deterministic; }),
      I("System.threads", [](O& o) -> int& { return o.num_threads; }),
  };
  return keys;
}

// ORB-SLAM2 keys planeloc reads but does not need (rectified KITTI: no distortion; no viewer).
bool IsIgnoredKey(const std::string& key) {
  static const std::vector<std::string> ignored = {
      "Camera.k1",  "Camera.k2",    "Camera.p1",     "Camera.p2",     "Camera.k3",
      "Camera.RGB", "Camera.width", "Camera.height", "DepthMapFactor"};
  for (const auto& k : ignored) {
    if (key == k) return true;
  }
  return key.rfind("Viewer.", 0) == 0 || key.rfind("LEFT.", 0) == 0 || key.rfind("RIGHT.", 0) == 0;
}

// yaml-cpp rejects OpenCV's `%YAML:1.0` directive (no space): drop directive lines.
std::string ReadWithoutDirectives(const std::filesystem::path& path) {
  std::ifstream in(path);
  CheckInput(in.good(), path.string(), 0, "cannot open the settings file",
             "check the path given to --config");
  std::ostringstream out;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("%YAML", 0) == 0) line = "";  // keep line numbers
    out << line << '\n';
  }
  return out.str();
}

// Fills `values` with scalar keys; nested maps become dotted keys ("Camera: {fx: ..}").
void Flatten(const YAML::Node& node, const std::string& prefix,
             std::vector<std::pair<std::string, YAML::Node>>& values) {
  for (const auto& item : node) {
    const std::string key = prefix + item.first.as<std::string>();
    if (item.second.IsMap()) {
      Flatten(item.second, key + ".", values);
    } else {
      values.emplace_back(key, item.second);
    }
  }
}

void CheckCamera(const std::string& key, double value, const StereoCamera& camera,
                 std::vector<std::string>& warnings) {
  double expected = 0;
  if (key == "Camera.fx")
    expected = camera.fx;
  else if (key == "Camera.fy")
    expected = camera.fy;
  else if (key == "Camera.cx")
    expected = camera.cx;
  else if (key == "Camera.cy")
    expected = camera.cy;
  else if (key == "Camera.bf")
    expected = camera.BaselineTimesFx();
  else
    return;
  if (std::abs(value - expected) > 0.01 * std::abs(expected) + 0.5) {
    warnings.push_back(fmt::format(
        "{} = {} differs from the sequence calibration ({:.4f}); the calibration is used", key,
        value, expected));
  }
}

}  // namespace

void TrackerOptions::Check() const {
  orb.Check();
  stereo.Check();
  pose.Check();
  ba.Check();
  Require(close_depth_baselines > 0, "close_depth_baselines must be > 0");
  Require(fps > 0, "fps must be > 0");
  Require(motion_search_radius > 0, "motion_search_radius must be > 0");
  Require(min_motion_matches >= 3, "min_motion_matches must be >= 3");
  Require(min_tracked_inliers >= 3, "min_tracked_inliers must be >= 3");
  Require(max_local_keyframes >= 1, "max_local_keyframes must be >= 1");
  Require(local_search_radius > 0, "local_search_radius must be > 0");
  Require(keyframe_tracked_ratio > 0 && keyframe_tracked_ratio <= 1,
          "keyframe_tracked_ratio must be in (0, 1]");
  Require(keyframe_min_close_tracked >= 0, "keyframe_min_close_tracked must be >= 0");
  Require(keyframe_min_close_untracked >= 0, "keyframe_min_close_untracked must be >= 0");
  Require(min_new_stereo_points >= 0, "min_new_stereo_points must be >= 0");
  Require(far_depth_baselines >= close_depth_baselines,
          "far_depth_baselines must be >= close_depth_baselines");
  Require(triangulation_neighbours >= 1, "triangulation_neighbours must be >= 1");
  Require(ba_window_keyframes >= 1, "ba_window_keyframes must be >= 1");
  Require(ba_max_fixed_keyframes >= 0, "ba_max_fixed_keyframes must be >= 0");
  Require(ba_window_keyframes_turn >= ba_window_keyframes,
          "ba_window_keyframes_turn must be >= ba_window_keyframes");
  Require(ba_turn_angle_deg > 0.0, "ba_turn_angle_deg must be > 0");
  planes.Check();
  Require(min_found_ratio >= 0 && min_found_ratio <= 1, "min_found_ratio must be in [0, 1]");
  Require(min_point_observations >= 1, "min_point_observations must be >= 1");
  Require(num_threads >= 1, "num_threads must be >= 1");
}

SettingsFile LoadTrackerSettings(const std::filesystem::path& path, const TrackerOptions& defaults,
                                 const std::optional<StereoCamera>& camera) {
  const std::string text = ReadWithoutDirectives(path);
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(path.string(), e.mark.line + 1, "not valid YAML: " + e.msg,
                     "fix the syntax (an ORB-SLAM2 settings file or planeloc keys)");
  }
  SettingsFile result;
  result.options = defaults;
  if (root.IsNull()) return result;
  CheckInput(root.IsMap(), path.string(), 0, "the settings file is not a map of keys",
             "write `Key: value` lines");
  std::vector<std::pair<std::string, YAML::Node>> values;
  Flatten(root, "", values);

  std::vector<std::string> errors;
  for (const auto& [name, node] : values) {
    const auto it =
        std::find_if(Keys().begin(), Keys().end(), [&](const Key& k) { return k.name == name; });
    const int line = node.Mark().line + 1;
    if (it == Keys().end()) {
      if (name.rfind("Camera.", 0) == 0 && !IsIgnoredKey(name) && camera) {
        try {
          CheckCamera(name, node.as<double>(), *camera, result.warnings);
          continue;
        } catch (const YAML::Exception&) {
          errors.push_back(fmt::format("line {}: {} must be a number", line, name));
          continue;
        }
      }
      if (!IsIgnoredKey(name) && name.rfind("Camera.", 0) != 0) {
        result.warnings.push_back(fmt::format("line {}: unknown key {} ignored", line, name));
      }
      continue;
    }
    try {
      switch (it->kind) {
        case Key::kDouble:
          it->real(result.options) = node.as<double>();
          break;
        case Key::kInt: {
          const double v = node.as<double>();
          if (v != std::floor(v)) throw YAML::Exception(node.Mark(), "not an integer");
          it->integer(result.options) = static_cast<int>(v);
          break;
        }
        case Key::kBool:
          it->flag(result.options) = node.as<bool>();
          break;
      }
    } catch (const YAML::Exception&) {
      const char* type = it->kind == Key::kDouble ? "a number"
                         : it->kind == Key::kInt  ? "an integer"
                                                  : "true or false";
      errors.push_back(fmt::format("line {}: {} must be {}", line, name, type));
    }
  }
  if (errors.empty()) {
    try {
      result.options.Check();
    } catch (const OptionsError& e) {
      errors.push_back(e.what());
    }
  }
  if (!errors.empty()) {
    std::string all;
    for (const auto& e : errors) all += (all.empty() ? "" : "; ") + e;
    throw InputError(path.string(), 0, "invalid settings: " + all,
                     "fix the listed keys (see docs/tracking.md for the key list)");
  }
  return result;
}

std::string TrackerSettingsYaml(const TrackerOptions& options, const StereoCamera& camera) {
  std::ostringstream out;
  out << "%YAML:1.0\n# planeloc effective tracker settings (read back with --config)\n";
  out << fmt::format("Camera.fx: {}\nCamera.fy: {}\nCamera.cx: {}\nCamera.cy: {}\n", camera.fx,
                     camera.fy, camera.cx, camera.cy);
  out << fmt::format("Camera.bf: {}\n", camera.BaselineTimesFx());
  TrackerOptions copy = options;
  for (const Key& key : Keys()) {
    switch (key.kind) {
      case Key::kDouble:
        out << fmt::format("{}: {}\n", key.name, key.real(copy));
        break;
      case Key::kInt:
        out << fmt::format("{}: {}\n", key.name, key.integer(copy));
        break;
      case Key::kBool:
        out << fmt::format("{}: {}\n", key.name, key.flag(copy) ? "true" : "false");
        break;
    }
  }
  return out.str();
}

void WriteTrackerSettings(const std::filesystem::path& path, const TrackerOptions& options,
                          const StereoCamera& camera) {
  std::ofstream out(path);
  CheckInput(out.good(), path.string(), 0, "cannot write the effective settings",
             "check that the output folder is writable");
  out << TrackerSettingsYaml(options, camera);
}

}  // namespace planeloc
