// The camera image of the live view: what the tracker sees in the frame it just tracked.
#pragma once

#include <opencv2/core.hpp>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/pipeline/tracker.h"

namespace planeloc::view {

// A colour per plane id, the same in the image and (as "#rrggbb") in the page's 3-D view.
cv::Scalar PlaneColorBgr(int plane_id);

// The frame's left image darkened, with
//  - the outlines of the map's planes projected at `world_from_cam` (clipped at 0.5 m in front of
//    the camera), each in its plane's colour, disabled planes in red;
//  - the tracked keypoints: on a plane (their map point within its band) in that plane's colour,
//    the others in white.
// `map` may be null (visual odometry). Returns a CV_8UC3 image the size of the frame's image, or
// an empty one when the view has no image.
cv::Mat DrawTrackedFrame(const TrackedFrameView& view, const StereoCamera& camera,
                         const Rigid3d& world_from_cam, const PlaneMap* map);

}  // namespace planeloc::view
