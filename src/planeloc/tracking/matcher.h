// Guided matching of 3-D points (map points, or points of the previous frame) to the keypoints
// of a frame by projection at a predicted pose, ORB-SLAM2's SearchByProjection as free
// functions: candidates within a radius (scaled by the pyramid level) on the expected levels,
// best Hamming distance under a threshold, optional ratio test, one match per keypoint (the
// closest descriptor wins) and an optional rotation-consistency histogram check.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/tracking/frame.h"
#include "planeloc/tracking/map.h"

namespace planeloc {

inline constexpr int kDescriptorThresholdHigh = 100;  // bits, ORB-SLAM2 TH_HIGH
inline constexpr int kDescriptorThresholdLow = 50;    // bits, ORB-SLAM2 TH_LOW

// A 3-D point to look for.
struct MatchSource {
  int map_point_id = -1;  // -1: a temporary point (e.g. a stereo point of the last frame)
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  cv::Mat descriptor;                 // 1 x 32
  int min_level = 0, max_level = -1;  // pyramid levels to search (max < 0: all)
  double radius = 10;                 // pixels at level 0 (already scaled by the caller)
  double angle = -1;                  // degrees: the source keypoint's orientation, < 0 if unknown
};

struct MatchOptions {
  int max_distance = kDescriptorThresholdHigh;
  double ratio = 1.0;                // best < ratio * second best (1 = no ratio test)
  bool ratio_across_levels = false;  // false: only a competitor on the same level counts
  bool check_orientation = false;    // rotation histogram consistency (needs source angles)
  bool check_right = true;           // for stereo keypoints, |u_R predicted - u_R| < radius
};

struct ProjectionMatch {
  int keypoint = 0;
  int source = 0;  // index into the sources
  int distance = 0;
};

// Matches sources to the keypoints of `frame` projected with `frame.cam_from_world`.
// Keypoints whose `frame.map_point_ids` entry is already set are skipped. Result sorted by
// keypoint index.
std::vector<ProjectionMatch> MatchByProjection(const std::vector<MatchSource>& sources,
                                               const Frame& frame, const StereoCamera& camera,
                                               const MatchOptions& options);

// Sources from the tracked keypoints of the previous frame: its map points and, where it has
// no map point, its close stereo points (temporary, ORB-SLAM2's "visual odometry" points). The
// level window follows the motion: forward motion searches at coarser levels, backward at finer.
std::vector<MatchSource> SourcesFromFrame(const Frame& last, const StereoCamera& camera,
                                          const SparseMap& map, const Rigid3d& cam_from_world_pred,
                                          double radius, double scale_factor, double close_depth);

// Sources from the map points of a keyframe (for the reference-keyframe fallback).
std::vector<MatchSource> SourcesFromKeyframe(const Keyframe& keyframe, const SparseMap& map,
                                             double radius, double scale_factor);

// Sources from local map points that are in the frame's view (ORB-SLAM2 isInFrustum: in
// front, inside the image, within the scale-invariance distances, viewing angle < 60 deg),
// with the predicted level and a radius of `radius_factor` x (2.5 or 4 by viewing angle) x
// the level's scale. `visible_point_ids` receives the ids that passed the view test.
std::vector<MatchSource> SourcesFromLocalMap(const std::vector<int>& point_ids,
                                             const SparseMap& map, const Frame& frame,
                                             const StereoCamera& camera, double radius_factor,
                                             std::vector<int>* visible_point_ids);

}  // namespace planeloc
