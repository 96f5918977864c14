// Options of the stereo tracker and their settings file.
//
// A settings file is OpenCV FileStorage YAML, as ORB-SLAM2 and ORB-SLAM3 read it (`%YAML:1.0`
// header, `key:value`, quoted strings, `!!opencv-matrix`): either ORB-SLAM layout (see
// settings_camera.h for the camera keys) and planeloc's own keys (`Tracking.*`, `LocalBA.*`,
// `Stereo.*`, `Planes.*`, ...). Every key is optional: built-in defaults apply. Keys that do not
// apply to planeloc (viewer, IMU, distortion of rectified images, ...) are listed as ignored;
// unknown keys are warnings; mistyped or invalid values are one InputError naming the file, the
// line, the key, the value and the expected form. The full key list is in docs/tracking.md.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/io/settings_camera.h"
#include "planeloc/optim/window_ba.h"
#include "planeloc/prior/map_lock_options.h"
#include "planeloc/prior/plane_association.h"
#include "planeloc/tracking/odometry_options.h"

namespace planeloc {

// The visual odometry's options and what the pipeline adds: the window BA's weights, the prior
// plane map, the map lock and threading.
struct TrackerOptions : OdometryOptions {
  WindowBaOptions ba = [] {
    WindowBaOptions o;
    o.lambda = 0.5;  // used only with a plane map, see `planes` below
    return o;
  }();

  // Threaded mode: a BA still running this many frames after it was submitted is waited for at
  // the start of the frame (0 = no bound). When frames come faster than the BA solves (an offline
  // run, the next frame's features extracted in parallel) the results otherwise land later and
  // later, and the frames in between track against the unadjusted map: kitti07-like seed 1, ATE
  // 0.096-0.138 m unbounded vs 0.064-0.077 m with 3 (deterministic 0.075 m), same fps. With 1 a
  // BA always lands at the frame after its keyframe, so the run no longer depends on timing: on
  // kitti07-like seeds 1, 2 and 3 (2 runs each) 1 gave 0.077 / 0.109 / 0.060 m, every run the
  // same, against deterministic 0.075 / 0.107 / 0.058 m, and 3 gave 0.066-0.072 / 0.070-0.162 /
  // 0.075-0.084 m, at 3 % more fps (44.0 vs 43.0 on seeds 1-2; docs/bench-tracking.md). At 10 Hz
  // in real time a BA lands within a frame or two and the bound never waits.
  int ba_max_lag_frames = 1;

  // With a plane map (`planeloc run --planes`): which map points lie on a LiDAR plane. The BA then
  // weighs reprojection by ba.lambda and point-to-plane by 1 - ba.lambda (LocalBA.lambda, default
  // 0.5 = both whitened terms weighted equally); without a plane map the BA is visual (lambda 1).
  PlaneAssociationOptions planes;
  // With a plane map and an uncertain start (--init-sigma): when and how the run registers its
  // structure to the plane map (prior/map_lock.h).
  MapLockOptions map_lock;

  // Deterministic: local BA in line on the tracking thread (bit-identical runs).
  bool deterministic = false;
  int num_threads = 2;  // threads for feature extraction (>= 1)
  // Ceres threads of the threaded local BA (LocalBA.threads); 0: num_threads. The tracker sets
  // ba.num_threads from this (one with `deterministic`). One by default:
  // the BA worker is already a thread beside the frame thread and the extraction, and a second
  // Ceres thread on 2 cores only oversubscribes them (kitti07-like seed 1, 5 alternated runs: 44.7
  // against 42.9 fps, ATE 0.085 against 0.091 m; docs/bench-tracking.md). `--deterministic` solves
  // with one whatever this says.
  int ba_threads = 1;

  // Throws OptionsError naming the field.
  void Check() const;
};

struct SettingsFile {
  TrackerOptions options;
  // The stereo calibration in the file (either layout), if any; see ChooseCamera.
  std::optional<SettingsCamera> camera;
  // System.calibrationFromSettings: use `camera` instead of the sequence's calibration.
  bool calibration_from_settings = false;
  std::vector<std::string> ignored;   // keys accepted but not applicable, each once, file order
  std::vector<std::string> warnings;  // unknown keys (with line), camera mismatches, ...
};

// Reads a settings file on top of `defaults`. Throws InputError (file, line, key, value and
// expected form) listing every mistyped or invalid key together, and for input planeloc cannot
// track (unrectified or fisheye stereo, see settings_camera.h). When `camera` (the sequence's
// calibration) is given, the file's calibration is compared with it (warnings only).
SettingsFile LoadTrackerSettings(const std::filesystem::path& path, const TrackerOptions& defaults,
                                 const std::optional<StereoCamera>& camera = std::nullopt);

// The effective configuration as a settings file that LoadTrackerSettings (and cv::FileStorage)
// reads back to the same values: ORB-SLAM3 v1.0 layout for the camera (Camera.type "Rectified",
// Camera1.*, Stereo.b, Camera.width/height), every planeloc key, and
// System.calibrationFromSettings. With a `rectifier` (raw images rectified on load) the camera is
// written in ORB-SLAM2's layout with LEFT/RIGHT K, D, R, P instead, so that a run with the
// written file rectifies the same way.
std::string TrackerSettingsYaml(const TrackerOptions& options, const StereoCamera& camera,
                                bool calibration_from_settings = false,
                                const StereoRectifier* rectifier = nullptr);
void WriteTrackerSettings(const std::filesystem::path& path, const TrackerOptions& options,
                          const StereoCamera& camera, bool calibration_from_settings = false,
                          const StereoRectifier* rectifier = nullptr);

}  // namespace planeloc
