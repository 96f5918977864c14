// The frame-to-map steps of ORB-SLAM2's tracking, as free functions over the sparse map: a
// constant-velocity prediction with a guided search against the last frame, the fallback
// against the reference keyframe, the pose-only optimisation, and the local-map search.
#pragma once

#include <vector>

#include "planeloc/features/orb_extractor.h"
#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/tracking/frame.h"
#include "planeloc/tracking/map.h"
#include "planeloc/tracking/odometry_options.h"

namespace planeloc {

// What every step reads besides the map: the camera, the ORB pyramid's level sigmas (the
// observations' weights) and the options.
struct TrackingContext {
  const StereoCamera& camera;
  const OrbExtractor& extractor;
  const OdometryOptions& options;
};

// Guided search for the last frame's map points and temporary stereo points around their
// projection at `predicted` (radius motion_search_radius, doubled once), then the pose from both
// together. False with fewer than min_motion_matches matches or 10 inliers; the frame then keeps
// `predicted` and may hold partial matches.
bool TrackWithMotionModel(const TrackingContext& context, const SparseMap& map, const Frame& last,
                          const Rigid3d& predicted, Frame& frame);

// The reference keyframe's points, searched in widening stages: around the prediction and around
// the last pose (with a velocity), then the whole image with a strict ratio test.
bool TrackWithReferenceKeyframe(const TrackingContext& context, const SparseMap& map,
                                int reference_keyframe_id, const Frame& last, bool has_velocity,
                                const Rigid3d& predicted, Frame& frame);

// Pose-only optimisation over the frame's matched map points: sets the frame's pose and outlier
// flags, drops matches to erased points; returns the inliers.
int OptimizeFramePose(const TrackingContext& context, const SparseMap& map, Frame& frame);

// The local map's points not yet matched in the frame: of the keyframes sharing points with it
// (most shared first, up to max_local_keyframes) and their covisible neighbours. Sets
// `reference_keyframe_id` to the keyframe sharing the most.
std::vector<int> LocalPointIds(const TrackingContext& context, const SparseMap& map,
                               const Frame& frame, int& reference_keyframe_id);

// Searches the local map's points in the frame, re-optimises its pose, and counts the points as
// visible / found (ORB-SLAM2's culling statistics). Returns the inliers.
int TrackLocalMap(const TrackingContext& context, SparseMap& map, Frame& frame,
                  int& reference_keyframe_id);

}  // namespace planeloc
