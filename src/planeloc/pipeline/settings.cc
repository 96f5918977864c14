#include "planeloc/pipeline/settings.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <map>
#include <regex>
#include <sstream>

#include "planeloc/io/settings_reader.h"
#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

namespace planeloc {
namespace {

void Require(bool condition, const std::string& what) {
  if (!condition) throw OptionsError("TrackerOptions: " + what);
}

// One settings key bound to a field of TrackerOptions.
struct Key {
  std::string name;  // written back under this name
  enum Kind { kInt, kDouble, kBool } kind;
  std::function<double&(TrackerOptions&)> real;  // kDouble
  std::function<int&(TrackerOptions&)> integer;  // kInt
  std::function<bool&(TrackerOptions&)> flag;    // kBool
  std::string alias = {};                        // also read under this name
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
      // ORB-SLAM2 ThDepth, ORB-SLAM3 Stereo.ThDepth.
      Key{"Stereo.ThDepth",
          Key::kDouble,
          [](O& o) -> double& { return o.close_depth_baselines; },
          {},
          {},
          "ThDepth"},
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
      I("Tracking.keyframeMinFrames", [](O& o) -> int& { return o.keyframe_min_frames; }),
      D("Tracking.keyframeMaxRotationDeg",
        [](O& o) -> double& { return o.keyframe_max_rotation_deg; }),
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
      B("Mapping.cullKeyframes", [](O& o) -> bool& { return o.maintenance.cull_keyframes; }),
      D("Mapping.cullRedundantRatio",
        [](O& o) -> double& { return o.maintenance.cull_redundant_ratio; }),
      I("Mapping.cullMinObservers", [](O& o) -> int& { return o.maintenance.cull_min_observers; }),
      I("Mapping.cullKeepNewest", [](O& o) -> int& { return o.maintenance.cull_keep_newest; }),
      B("Mapping.fusePoints", [](O& o) -> bool& { return o.maintenance.fuse_points; }),
      I("Mapping.fuseNeighbours", [](O& o) -> int& { return o.maintenance.fuse_neighbours; }),
      D("Mapping.fuseRadius", [](O& o) -> double& { return o.maintenance.fuse_radius; }),
      I("Mapping.keepKeyframes", [](O& o) -> int& { return o.maintenance.keep_keyframes; }),
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
      I("LocalBA.maxLagFrames", [](O& o) -> int& { return o.ba_max_lag_frames; }),
      I("LocalBA.threads", [](O& o) -> int& { return o.ba_threads; }),
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
      D("Planes.biasPeerAngleDeg", [](O& o) -> double& { return o.planes.bias_peer_angle_deg; }),
      B("Planes.trajectoryConsensus", [](O& o) -> bool& { return o.planes.trajectory_consensus; }),
      I("Planes.consensusMinPlanes", [](O& o) -> int& { return o.planes.consensus_min_planes; }),
      I("Planes.consensusMinPoints", [](O& o) -> int& { return o.planes.consensus_min_points; }),
      D("Planes.consensusMinOffset", [](O& o) -> double& { return o.planes.consensus_min_offset; }),
      D("Planes.consensusTolerance", [](O& o) -> double& { return o.planes.consensus_tolerance; }),
      // Map registration and lock from a coarse start (docs/map-registration.md).
      I("MapLock.attemptEveryKeyframes",
        [](O& o) -> int& { return o.map_lock.attempt_every_keyframes; }),
      I("MapLock.structureKeyframes", [](O& o) -> int& { return o.map_lock.structure_keyframes; }),
      D("MapLock.maxPointDistance", [](O& o) -> double& { return o.map_lock.max_point_distance; }),
      D("MapLock.disparitySigma", [](O& o) -> double& { return o.map_lock.disparity_sigma_px; }),
      D("MapLock.driftFraction", [](O& o) -> double& { return o.map_lock.drift_fraction; }),
      D("MapLock.driftYawDegPer100m",
        [](O& o) -> double& { return o.map_lock.drift_yaw_deg_per_100m; }),
      D("MapLock.lostSigmaHorizontal",
        [](O& o) -> double& { return o.map_lock.lost_sigma_horizontal; }),
      D("MapLock.lostSigmaVertical",
        [](O& o) -> double& { return o.map_lock.lost_sigma_vertical; }),
      D("MapLock.lostSigmaYawDeg", [](O& o) -> double& { return o.map_lock.lost_sigma_yaw_deg; }),
      I("MapLock.settleKeyframes", [](O& o) -> int& { return o.map_lock.settle_keyframes; }),
      I("MapLock.maintainEveryKeyframes",
        [](O& o) -> int& { return o.map_lock.maintain_every_keyframes; }),
      D("MapLock.maintainSigmaHorizontal",
        [](O& o) -> double& { return o.map_lock.maintain_sigma_horizontal; }),
      D("MapLock.maintainSigmaVertical",
        [](O& o) -> double& { return o.map_lock.maintain_sigma_vertical; }),
      D("MapLock.maintainSigmaYawDeg",
        [](O& o) -> double& { return o.map_lock.maintain_sigma_yaw_deg; }),
      D("MapLock.minRecorrection", [](O& o) -> double& { return o.map_lock.min_recorrection; }),
      D("MapLock.recorrectionSigmas",
        [](O& o) -> double& { return o.map_lock.recorrection_sigmas; }),
      D("MapLock.minRecorrectionDeg",
        [](O& o) -> double& { return o.map_lock.min_recorrection_deg; }),
      D("MapLock.maxCorrectionSigmas",
        [](O& o) -> double& { return o.map_lock.max_correction_sigmas; }),
      D("MapLock.minCorrectionSigmas",
        [](O& o) -> double& { return o.map_lock.min_correction_sigmas; }),
      D("MapLock.minInlierRatio",
        [](O& o) -> double& { return o.map_lock.registration.min_inlier_ratio; }),
      D("MapLock.maxWhitenedRms",
        [](O& o) -> double& { return o.map_lock.registration.max_whitened_rms; }),
      D("MapLock.minMargin", [](O& o) -> double& { return o.map_lock.registration.min_margin; }),
      D("MapLock.maxDofSigma",
        [](O& o) -> double& { return o.map_lock.registration.max_dof_sigma; }),
      D("MapLock.maxYawSigmaDeg",
        [](O& o) -> double& { return o.map_lock.registration.max_dof_sigma_deg; }),
      D("MapLock.maxTiltSigmaDeg",
        [](O& o) -> double& { return o.map_lock.registration.max_tilt_sigma_deg; }),
      D("MapLock.noiseInflation",
        [](O& o) -> double& { return o.map_lock.registration.noise_inflation; }),
      D("MapLock.mapSigma", [](O& o) -> double& { return o.map_lock.registration.map_sigma; }),
      D("MapLock.outlineMargin",
        [](O& o) -> double& { return o.map_lock.registration.outline_margin; }),
      B("Planes.creaseCheck", [](O& o) -> bool& { return o.planes.crease_check; }),
      I("Planes.lsdLevel", [](O& o) -> int& { return o.planes.crease.lsd_level; }),
      B("Planes.lsdStrips", [](O& o) -> bool& { return o.planes.crease.lsd_strips; }),
      D("Planes.creaseConfirmPx", [](O& o) -> double& { return o.planes.crease.confirm_px; }),
      D("MapUpdate.band", [](O& o) -> double& { return o.map_update.band; }),
      I("MapUpdate.minPoints", [](O& o) -> int& { return o.map_update.min_points; }),
      D("MapUpdate.trajectorySigma", [](O& o) -> double& { return o.map_update.trajectory_sigma; }),
      D("MapUpdate.trajectoryTiltSigmaDeg",
        [](O& o) -> double& { return o.map_update.trajectory_tilt_sigma_deg; }),
      D("MapUpdate.minOffset", [](O& o) -> double& { return o.map_update.min_offset; }),
      D("MapUpdate.minTiltDeg", [](O& o) -> double& { return o.map_update.min_tilt_deg; }),
      D("MapUpdate.chi2", [](O& o) -> double& { return o.map_update.chi2; }),
      I("DepthPrior.downsample", [](O& o) -> int& { return o.depth.stereo.downsample; }),
      I("DepthPrior.maxDisparity", [](O& o) -> int& { return o.depth.stereo.max_disparity; }),
      I("DepthPrior.blockSize", [](O& o) -> int& { return o.depth.stereo.block_size; }),
      D("DepthPrior.voxelSize", [](O& o) -> double& { return o.depth.voxel_size; }),
      D("DepthPrior.maxRange", [](O& o) -> double& { return o.depth.max_range; }),
      D("DepthPrior.minDepth", [](O& o) -> double& { return o.depth.min_depth; }),
      D("DepthPrior.disparitySigma", [](O& o) -> double& { return o.depth.disparity_sigma; }),
      D("DepthPrior.weight", [](O& o) -> double& { return o.depth.weight; }),
      I("DepthPrior.sampleCell", [](O& o) -> int& { return o.depth.sample_cell; }),
      I("DepthPrior.maxPoints", [](O& o) -> int& { return o.depth.max_points; }),
      D("DepthPrior.occlusionMargin", [](O& o) -> double& { return o.depth.occlusion_margin; }),
      D("DepthPrior.edgeTolerance", [](O& o) -> double& { return o.depth.edge_tolerance; }),
      D("DepthPrior.maxCorrection", [](O& o) -> double& { return o.depth.max_correction; }),
      D("DepthPrior.maxCorrectionDeg", [](O& o) -> double& { return o.depth.max_correction_deg; }),
      B("DepthPrior.frameRefinement", [](O& o) -> bool& { return o.depth.frame_refinement; }),
      B("DepthPrior.windowSurfaces", [](O& o) -> bool& { return o.depth.window_surfaces; }),
      D("DepthPrior.surfaceRadius", [](O& o) -> double& { return o.depth.surfaces.radius; }),
      I("DepthPrior.surfaceMinPoints", [](O& o) -> int& { return o.depth.surfaces.min_points; }),
      D("DepthPrior.surfaceMaxThickness",
        [](O& o) -> double& { return o.depth.surfaces.max_thickness; }),
      D("DepthPrior.surfaceMinSpread", [](O& o) -> double& { return o.depth.surfaces.min_spread; }),
      B("System.deterministic", [](O& o) -> bool& { return o.deterministic; }),
      I("System.threads", [](O& o) -> int& { return o.num_threads; }),
  };
  return keys;
}

// Keys of ORB-SLAM settings that do not apply to planeloc: accepted and listed as ignored.
bool IsNotApplicable(const std::string& key) {
  static const std::vector<std::string> exact = {"Camera.RGB",
                                                 "Camera.bFishEye",
                                                 "DepthMapFactor",
                                                 "RGBD.DepthMapFactor",
                                                 "System.LoadAtlasFromFile",
                                                 "System.SaveAtlasToFile",
                                                 "System.thFarPoints",
                                                 "loopClosing",
                                                 "InsertKFsWhenLost",
                                                 "Tbc",
                                                 "Tlr"};
  static const std::vector<std::string> prefixes = {"Viewer.", "IMU.", "PointCloudMapping."};
  static const std::vector<std::string> distortion = {"k1", "k2", "k3", "k4", "p1", "p2"};
  if (std::find(exact.begin(), exact.end(), key) != exact.end()) return true;
  for (const auto& prefix : prefixes) {
    if (key.rfind(prefix, 0) == 0) return true;
  }
  for (const char* camera : {"Camera.", "Camera1.", "Camera2."}) {
    for (const auto& k : distortion) {
      if (key == camera + k) return true;
    }
  }
  return false;
}

void ReadKey(SettingsReader& reader, const Key& key, const std::string& name,
             TrackerOptions& options) {
  switch (key.kind) {
    case Key::kDouble:
      if (const auto v = reader.Number(name)) key.real(options) = *v;
      break;
    case Key::kInt:
      if (const auto v = reader.Integer(name)) key.integer(options) = *v;
      break;
    case Key::kBool:
      if (const auto v = reader.Flag(name)) key.flag(options) = *v;
      break;
  }
}

// The planeloc keys present in the file, in table order (an alias before its main name).
std::vector<std::pair<const Key*, std::string>> PresentKeys(const SettingsReader& reader) {
  std::vector<std::pair<const Key*, std::string>> present;
  for (const Key& key : Keys()) {
    for (const std::string& name : {key.alias, key.name}) {
      if (!name.empty() && reader.Has(name)) present.emplace_back(&key, name);
    }
  }
  return present;
}

// Applies the keys one at a time to find the one whose value makes TrackerOptions::Check fail.
void ReportInvalidValues(SettingsReader& reader, const TrackerOptions& defaults) {
  TrackerOptions options = defaults;
  for (const auto& [key, name] : PresentKeys(reader)) {
    ReadKey(reader, *key, name, options);
    try {
      options.Check();
    } catch (const OptionsError& e) {
      // The key is named: drop the options struct's name ("OrbOptions: num_features ...").
      const std::string rule =
          std::regex_replace(e.what(), std::regex("[A-Za-z]+Options(: |\\.)"), "");
      reader.AddError(name, fmt::format("a valid value ({})", rule));
      options = defaults;
    }
  }
}

// An !!opencv-matrix with doubles in shortest round-trip form.
void WriteMatrix(std::ostream& out, const std::string& key, const cv::Mat& m) {
  out << key << ": !!opencv-matrix\n";
  out << fmt::format("  rows: {}\n  cols: {}\n  dt: d\n  data: [", m.rows, m.cols);
  for (int r = 0; r < m.rows; ++r) {
    for (int c = 0; c < m.cols; ++c) {
      out << (r + c > 0 ? ", " : "") << fmt::format("{}", m.at<double>(r, c));
    }
  }
  out << "]\n";
}

void WriteRawSide(std::ostream& out, const std::string& side, const RawCamera& camera,
                  const cv::Mat& r, const cv::Mat& p, cv::Size size) {
  out << fmt::format("{0}.width: {1}\n{0}.height: {2}\n", side, size.width, size.height);
  WriteMatrix(out, side + ".K", camera.k);
  WriteMatrix(out, side + ".D", camera.d.reshape(1, 1));
  WriteMatrix(out, side + ".R", r);
  WriteMatrix(out, side + ".P", p);
}

}  // namespace

void TrackerOptions::Check() const {
  OdometryOptions::Check();
  ba.Check();
  Require(ba_max_lag_frames >= 0, "ba_max_lag_frames (LocalBA.maxLagFrames) must be >= 0");
  planes.Check();
  map_lock.Check();
  map_update.Check();
  depth.Check();
  Require(num_threads >= 1, "num_threads must be >= 1");
  Require(ba_threads >= 0, "ba_threads (LocalBA.threads) must be >= 0");
}

SettingsFile LoadTrackerSettings(const std::filesystem::path& path, const TrackerOptions& defaults,
                                 const std::optional<StereoCamera>& camera) {
  constexpr const char* kFix = "fix the listed keys (see docs/tracking.md for the accepted keys)";
  SettingsReader reader(path);
  SettingsFile result;
  result.options = defaults;
  result.camera = ReadSettingsCamera(reader, &result.warnings);
  result.calibration_from_settings = reader.Flag("System.calibrationFromSettings").value_or(false);

  std::map<const void*, std::string> set_by;  // field -> key that set it
  for (const auto& [key, name] : PresentKeys(reader)) {
    ReadKey(reader, *key, name, result.options);
    const void* field =
        key->kind == Key::kDouble ? static_cast<const void*>(&key->real(result.options))
        : key->kind == Key::kInt  ? static_cast<const void*>(&key->integer(result.options))
                                  : static_cast<const void*>(&key->flag(result.options));
    const auto [it, inserted] = set_by.emplace(field, name);
    if (!inserted) {
      result.warnings.push_back(
          fmt::format("line {}: {} and {} (line {}) are the same setting; {} is used",
                      reader.LineOf(name), name, it->second, reader.LineOf(it->second), name));
      it->second = name;
    }
  }
  reader.ThrowIfErrors(kFix);
  try {
    result.options.Check();
  } catch (const OptionsError&) {
    ReportInvalidValues(reader, defaults);
    if (!reader.HasErrors()) throw;  // defaults alone invalid: not the file's fault
  }
  reader.ThrowIfErrors(kFix);

  std::map<std::string, int> seen;
  for (const SettingsReader::Entry& entry : reader.entries()) {
    if (++seen[entry.key] == 2) {
      result.warnings.push_back(fmt::format(
          "line {}: {} is given more than once; the last value is used", entry.line, entry.key));
    }
  }
  // The distortion of an ORB-SLAM3 PinHole pair that is rectified on load is used.
  const bool raw_pinhole_pair =
      result.camera && result.camera->rectifier && result.camera->layout == "ORB-SLAM3";
  auto used_distortion = [&](const std::string& key) {
    return raw_pinhole_pair && (key.rfind("Camera1.", 0) == 0 || key.rfind("Camera2.", 0) == 0);
  };
  std::map<std::string, bool> listed;
  for (const SettingsReader::Entry& entry : reader.entries()) {
    if (listed[entry.key]) continue;
    listed[entry.key] = true;
    if (IsNotApplicable(entry.key) && !used_distortion(entry.key)) {
      result.ignored.push_back(entry.key);
    } else if (!entry.used) {
      result.warnings.push_back(
          fmt::format("line {}: unknown key {} ignored", entry.line, entry.key));
    }
  }
  if (camera && !(result.camera && result.camera->rectifier)) {
    ChooseCamera(*camera, result.camera, false, path, &result.warnings);
  }
  return result;
}

std::string TrackerSettingsYaml(const TrackerOptions& options, const StereoCamera& camera,
                                bool calibration_from_settings, const StereoRectifier* rectifier) {
  std::ostringstream out;
  out << "%YAML:1.0\n"
         "# planeloc effective tracker settings (OpenCV FileStorage YAML); read back with\n"
         "# `planeloc run --config`.\n";
  if (rectifier) {
    out << "# Raw stereo images, rectified on load (ORB-SLAM2 layout: LEFT/RIGHT K, D, R, P).\n";
    out << fmt::format("Camera.fx: {}\nCamera.fy: {}\nCamera.cx: {}\nCamera.cy: {}\n", camera.fx,
                       camera.fy, camera.cx, camera.cy);
    out << fmt::format("Camera.bf: {}\n", camera.BaselineTimesFx());
    WriteRawSide(out, "LEFT", rectifier->left(), rectifier->left_r(), rectifier->left_p(),
                 rectifier->size());
    WriteRawSide(out, "RIGHT", rectifier->right(), rectifier->right_r(), rectifier->right_p(),
                 rectifier->size());
  } else {
    out << "File.version: \"1.0\"\nCamera.type: \"Rectified\"\n";
    out << fmt::format("Camera1.fx: {}\nCamera1.fy: {}\nCamera1.cx: {}\nCamera1.cy: {}\n",
                       camera.fx, camera.fy, camera.cx, camera.cy);
    out << fmt::format("Stereo.b: {}\n", camera.baseline);
  }
  out << fmt::format("Camera.width: {}\nCamera.height: {}\n", camera.width, camera.height);
  out << fmt::format("System.calibrationFromSettings: {}\n", calibration_from_settings ? 1 : 0);
  TrackerOptions copy = options;
  for (const Key& key : Keys()) {
    switch (key.kind) {
      case Key::kDouble:
        out << fmt::format("{}: {}\n", key.name, key.real(copy));
        break;
      case Key::kInt:
        out << fmt::format("{}: {}\n", key.name, key.integer(copy));
        break;
      case Key::kBool:  // 0/1: cv::FileStorage reads true/false as strings
        out << fmt::format("{}: {}\n", key.name, key.flag(copy) ? 1 : 0);
        break;
    }
  }
  return out.str();
}

void WriteTrackerSettings(const std::filesystem::path& path, const TrackerOptions& options,
                          const StereoCamera& camera, bool calibration_from_settings,
                          const StereoRectifier* rectifier) {
  WriteFileWhole(path, TrackerSettingsYaml(options, camera, calibration_from_settings, rectifier));
}

}  // namespace planeloc
