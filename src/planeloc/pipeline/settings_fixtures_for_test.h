// Settings files written for the settings tests (settings_test.cc, settings_rig_test.cc,
// settings_run_test.cc) and the helpers they share.
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/pipeline/settings.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace settings_test {

// The simulator's camera: KITTI odometry sequences 04-12 (bf = 379.708).
inline StereoCamera TestCamera() { return sim::Kitti07Camera(); }

inline std::filesystem::path WriteFile(const TempDir& dir, const std::string& text,
                                       const std::string& name = "settings.yaml") {
  const auto path = dir.path() / name;
  std::ofstream(path) << text;
  return path;
}

inline bool Contains(const std::vector<std::string>& list, const std::string& needle) {
  for (const auto& item : list) {
    if (item.find(needle) != std::string::npos) return true;
  }
  return false;
}

inline std::string Message(const std::function<void()>& load) {
  try {
    load();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError";
  return "";
}

// Fixtures written for these tests in the layouts of ORB-SLAM2's and ORB-SLAM3's stereo examples,
// with their quirks: `%YAML:1.0`, `key:value` without a space, quoted strings, !!opencv-matrix,
// `data:[...]`, viewer keys. They all describe the simulator's camera and the same options:
// close depth 35 baselines, 1500 features, FAST thresholds 12/7.

// ORB-SLAM2 (and ORB-SLAM3 before v1.0) stereo layout.
inline constexpr const char* kOrbSlam2 = R"(%YAML:1.0

#---------------------------------------------
# Camera (rectified KITTI-like pair)
#---------------------------------------------
Camera.type: "PinHole"
Camera.fx: 707.0912
Camera.fy: 707.0912
Camera.cx: 601.8873
Camera.cy: 183.1104
Camera.k1: 0.0
Camera.k2: 0.0
Camera.p1: 0.0
Camera.p2: 0.0
Camera.bFishEye:0
Camera.width: 1226
Camera.height: 370
Camera.fps:10.0
Camera.bf: 379.708
Camera.RGB:1
ThDepth: 35

# ORB
ORBextractor.nFeatures: 1500
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 12
ORBextractor.minThFAST:7

# Viewer
Viewer.KeyFrameSize: 0.5
Viewer.PointSize:3
Viewer.ViewpointY: -90
)";

// ORB-SLAM3 v1.0, rectified pair (Camera.type "Rectified", Stereo.b).
inline constexpr const char* kOrbSlam3Rectified = R"(%YAML:1.0
File.version: "1.0"

Camera.type: "Rectified"
Camera1.fx: 707.0912
Camera1.fy: 707.0912
Camera1.cx: 601.8873
Camera1.cy: 183.1104
Camera.width: 1226
Camera.height: 370
Camera.newWidth: 1226
Camera.newHeight: 370
Camera.fps: 10
Camera.RGB: 1
Stereo.ThDepth: 35.0
Stereo.b: 0.537

ORBextractor.nFeatures: 1500
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 12
ORBextractor.minThFAST: 7

Viewer.KeyFrameSize: 0.05
Viewer.PointSize:2
Viewer.imageViewScale: 1.0
System.thFarPoints: 20.0
)";

// ORB-SLAM3 v1.0, "PinHole" pair with Camera2 and Stereo.T_c1_c2 that happens to be rectified.
inline constexpr const char* kOrbSlam3PinHole = R"(%YAML:1.0
File.version: "1.0"
Camera.type: "PinHole"

Camera1.fx: 707.0912
Camera1.fy: 707.0912
Camera1.cx: 601.8873
Camera1.cy: 183.1104
Camera1.k1: 0.0
Camera1.k2: 0.0
Camera1.p1: 0.0
Camera1.p2: 0.0

Camera2.fx: 707.0912
Camera2.fy: 707.0912
Camera2.cx: 601.8873
Camera2.cy: 183.1104
Camera2.k1: 0.0
Camera2.k2: 0.0
Camera2.p1: 0.0
Camera2.p2: 0.0

Camera.width: 1226
Camera.height: 370
Camera.fps: 10
Camera.RGB: 1

Stereo.ThDepth: 35.0
Stereo.T_c1_c2: !!opencv-matrix
  rows: 4
  cols: 4
  dt: d
  data:[1.0, 0.0, 0.0, 0.537,
        0.0, 1.0, 0.0, 0.0,
        0.0, 0.0, 1.0, 0.0,
        0.0, 0.0, 0.0, 1.0]

ORBextractor.nFeatures: 1500
ORBextractor.scaleFactor: 1.2
ORBextractor.nLevels: 8
ORBextractor.iniThFAST: 12
ORBextractor.minThFAST: 7

Viewer.PointSize: 2
)";

// The same options as planeloc keys only (no header, no camera).
inline constexpr const char* kPlanelocKeys = R"(Stereo.ThDepth: 35
ORBextractor.nFeatures: 1500
ORBextractor.iniThFAST: 12
ORBextractor.minThFAST: 7
Camera.fps: 10
)";

inline void ExpectFixtureOptions(const SettingsFile& file) {
  EXPECT_DOUBLE_EQ(file.options.close_depth_baselines, 35.0);
  EXPECT_EQ(file.options.orb.num_features, 1500);
  EXPECT_EQ(file.options.orb.initial_fast_threshold, 12);
  EXPECT_EQ(file.options.orb.min_fast_threshold, 7);
  EXPECT_EQ(file.options.orb.num_levels, 8);
  EXPECT_DOUBLE_EQ(file.options.fps, 10.0);
}

// ORB-SLAM2 EuRoC-style raw rig (numbers made up, EuRoC-like): LEFT/RIGHT K, D, R, P.
inline constexpr const char* kOrbSlam2RawRig = R"(%YAML:1.0
Camera.type: "PinHole"
Camera.fx: 436.0
Camera.fy: 436.0
Camera.cx: 367.5
Camera.cy: 252.0
Camera.k1: 0.0
Camera.k2: 0.0
Camera.p1: 0.0
Camera.p2: 0.0
Camera.width: 752
Camera.height: 480
Camera.fps: 20.0
Camera.bf: 47.96
Camera.RGB: 1
ThDepth: 35

# Rectification of the raw images.
LEFT.height: 480
LEFT.width: 752
LEFT.D: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data:[-0.28, 0.074, 2.0e-4, 2.0e-5, 0.0]
LEFT.K: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [458.0, 0.0, 367.0, 0.0, 457.0, 248.0, 0.0, 0.0, 1.0]
LEFT.R:  !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [0.99997, -0.0014, 0.0081, 0.0014, 0.99997, 0.0071, -0.0081, -0.0071, 0.99994]
LEFT.P:  !!opencv-matrix
   rows: 3
   cols: 4
   dt: d
   data: [436.0, 0, 367.5, 0,  0, 436.0, 252.0, 0,  0, 0, 1, 0]

RIGHT.height: 480
RIGHT.width: 752
RIGHT.D: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data:[-0.283, 0.0745, -1.0e-4, -3.5e-5, 0.0]
RIGHT.K: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [457.5, 0.0, 380.0, 0.0, 456.0, 255.0, 0.0, 0.0, 1]
RIGHT.R:  !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [0.99996, -0.0036, 0.0078, 0.0037, 0.99997, -0.0070, -0.0077, 0.0071, 0.99995]
RIGHT.P:  !!opencv-matrix
   rows: 3
   cols: 4
   dt: d
   data: [436.0, 0, 367.5, -47.96, 0, 436.0, 252.0, 0, 0, 0, 1, 0]

ORBextractor.nFeatures: 1200
Viewer.PointSize:2
)";

}  // namespace settings_test
}  // namespace planeloc
