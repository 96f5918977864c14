// The stereo calibration of a settings file, in either ORB-SLAM layout, and the choice between it
// and the sequence's calibration.
//
//   ORB-SLAM2 (and ORB-SLAM3 before v1.0): Camera.fx/fy/cx/cy, Camera.bf (baseline x fx),
//     optional Camera.type "PinHole", Camera.k1/k2/p1/p2/k3 (ignored: rectified images),
//     Camera.width/height. LEFT.K/D/R/P/width/height and RIGHT.* (as in EuRoC.yaml) describe
//     raw images: they are rectified on load with these maps (the rectified camera is LEFT.P /
//     RIGHT.P).
//   ORB-SLAM3 v1.0: File.version "1.0", Camera.type "Rectified" (Camera1.fx/fy/cx/cy, Stereo.b)
//     or "PinHole" (Camera1.* with k1/k2/p1/p2[/k3], Camera2.*, Stereo.T_c1_c2 = c1_from_c2 as a
//     4x4 !!opencv-matrix). A PinHole pair that is already rectified (same intrinsics, no
//     distortion, identity rotation, translation along +x) is used as is; any other is rectified
//     on load (cv::stereoRectify, as ORB-SLAM3). KannalaBrandt8 (fisheye) is refused;
//     Camera.newWidth/newHeight (resizing) is refused unless equal to Camera.width/height.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/io/settings_reader.h"
#include "planeloc/io/stereo_rectifier.h"

namespace planeloc {

struct SettingsCamera {
  std::string layout;                     // "ORB-SLAM2" or "ORB-SLAM3"
  double fx = 0, fy = 0, cx = 0, cy = 0;  // pixels, rectified
  double baseline = 0;                    // metres, right camera at +baseline along x
  int width = 0, height = 0;              // pixels; 0 when the file gives none
  // Keys the values came from (for messages): e.g. "Camera.fx" or "Camera1.fx", and "Camera.bf",
  // "Stereo.b" or "Stereo.T_c1_c2" for the baseline.
  std::string fx_key, fy_key, cx_key, cy_key, baseline_key;
  int line = 0;  // line of fx_key
  // Set when the file describes raw images: they are rectified on load with it, and the fields
  // above are its rectified camera (the settings' calibration is then always used).
  std::shared_ptr<const StereoRectifier> rectifier;
};

// Reads the calibration keys of either layout. Mistyped and missing companion keys are recorded
// in `reader`; nonzero distortion of rectified images and an unknown File.version are warnings.
// Returns nullopt when the file carries no intrinsics. Throws InputError (file, line, exit 2)
// for input planeloc cannot track (fisheye stereo, resized images) or an unusable raw rig.
std::optional<SettingsCamera> ReadSettingsCamera(SettingsReader& reader,
                                                 std::vector<std::string>* warnings);

// The camera of a run. The sequence's calibration (calib.txt / calib_cam_to_cam.txt) by default;
// the settings' intrinsics and baseline when `from_settings` (image size from the sequence).
// A difference of more than 0.5 px in fx/fy/cx/cy or 0.5 % in baseline is a warning showing both
// values. With a rectifier the settings' camera is used, and the images must have its size.
// Throws InputError when `from_settings` and the file carries no calibration, or the images do
// not have the size of the raw rig.
StereoCamera ChooseCamera(const StereoCamera& sequence, const std::optional<SettingsCamera>& file,
                          bool from_settings, const std::filesystem::path& settings_path,
                          std::vector<std::string>* warnings);

}  // namespace planeloc
