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
#include "planeloc/prior/depth_prior_options.h"
#include "planeloc/prior/map_lock_options.h"
#include "planeloc/prior/plane_association.h"
#include "planeloc/prior/plane_evidence.h"
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
  // the start of the frame (0 = no bound; LocalBA.maxLagFrames). 1: every BA lands at the frame
  // after its keyframe, so runs do not depend on timing (measured in docs/bench-tracking.md).
  int ba_max_lag_frames = 1;

  // With a plane map (`planeloc run --planes`): which map points lie on a LiDAR plane. The BA then
  // weighs reprojection by ba.lambda and point-to-plane by 1 - ba.lambda (LocalBA.lambda, default
  // 0.5 = both whitened terms weighted equally); without a plane map the BA is visual (lambda 1).
  PlaneAssociationOptions planes;
  // With a plane map and an uncertain start (--init-sigma): when and how the run registers its
  // structure to the plane map (prior/map_lock.h).
  MapLockOptions map_lock;
  // `planeloc run --map-update`: what the run learns about each plane (prior/plane_evidence.h).
  bool record_plane_evidence = false;  // not a settings key: the run's --map-update turns it on
  PlaneEvidenceOptions map_update;
  // With a map cloud (`planeloc run --map-cloud map.pcd --prior depth`): the depth-to-map
  // residual in each frame's pose optimisation (prior/depth_prior.h).
  DepthPriorOptions depth;

  // Deterministic: local BA in line on the tracking thread (bit-identical runs).
  bool deterministic = false;
  int num_threads = 2;  // threads for feature extraction (>= 1)
  // Ceres threads of the threaded local BA (LocalBA.threads); 0: num_threads. One: the BA worker
  // already runs beside the frame thread (docs/bench-tracking.md); deterministic runs use one.
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
