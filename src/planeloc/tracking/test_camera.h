// A round-numbered rectified stereo camera for tracking tests on hand-made features.
#pragma once

#include "planeloc/geometry/camera.h"

namespace planeloc::testing {

inline StereoCamera RoundStereoCamera() {
  return StereoCamera{
      .fx = 700, .fy = 700, .cx = 600, .cy = 185, .baseline = 0.5, .width = 1200, .height = 370};
}

}  // namespace planeloc::testing
