// Keyframe images for `planeloc report` (written by `planeloc run --report-dir`): what the plane
// constraints see in one keyframe, drawn on its left image.
#pragma once

#include <opencv2/core.hpp>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/pipeline/settings.h"

namespace planeloc {

struct KeyframeOverlayCounts {
  int features = 0;        // ORB features of the left image
  int with_depth = 0;      // of them, with a stereo depth
  int on_planes = 0;       // of those, on a map plane (in its image region and near it in 3-D)
  int segments = 0;        // LSD segments drawn
  int planes_in_view = 0;  // planes with an image region
};

// The left image (grey, rectified) darkened, with
//  - the image regions of the map's planes at `world_from_cam` (RenderPlaneLabels of the crease
//    check: nearest plane per cell, so occluded parts are not drawn), tinted and outlined, each
//    plane in its own colour;
//  - the LSD segments of the left image (white);
//  - the ORB features: with a stereo depth that puts them within
//    max(0.25 m, 2% of the depth) of the plane their pixel shows, in that plane's colour; others
//    grey.
// `map` may be null (visual odometry): segments and features only. Returns a CV_8UC3 image.
cv::Mat DrawKeyframeOverlay(const cv::Mat& left, const cv::Mat& right, const StereoCamera& camera,
                            const Rigid3d& world_from_cam, const PlaneMap* map,
                            const TrackerOptions& options, KeyframeOverlayCounts* counts = nullptr);

}  // namespace planeloc
