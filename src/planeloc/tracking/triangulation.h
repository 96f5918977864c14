// New map points by triangulating a new keyframe's unmatched keypoints against its covisible
// neighbours (ORB-SLAM2 LocalMapping::CreateNewMapPoints). Stereo depth alone only creates points
// up to the far depth; triangulation over the wider keyframe baseline adds distant and
// stereo-less keypoints, which constrain rotation and keep more points tracked.
//
// Without a bag of words, candidate pairs are restricted by the epipolar constraint from the
// known poses (distance to the epipolar line below chi2(1 dof, 95 %) * sigma^2 of the level),
// then by descriptor distance (<= kDescriptorThresholdLow) and a nearest-neighbour ratio test.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <utility>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/tracking/map.h"

namespace planeloc {

struct TriangulationOptions {
  int num_neighbours = 10;                 // best covisible keyframes (ORB-SLAM2 stereo: 10)
  double min_baseline_depth_ratio = 0.01;  // baseline / median scene depth of the neighbour
  int max_descriptor_distance = 50;        // bits (ORB-SLAM2 TH_LOW)
  double ratio = 0.6;                      // best < ratio * second best
  double epipolar_chi2 = 3.84;             // squared px / sigma^2 to the epipolar line
  double mono_chi2 = 5.991;                // 2 dof reprojection check
  double stereo_chi2 = 7.8;                // 3 dof (u_L, v, u_R) reprojection check
  double scale_ratio_slack = 1.5;          // times the pyramid scale factor
};

// Pairs (keypoint in a, keypoint in b) of keypoints without map points that satisfy the
// epipolar constraint and the descriptor tests; each keypoint appears at most once.
std::vector<std::pair<int, int>> MatchForTriangulation(const Keyframe& a, const Keyframe& b,
                                                       const StereoCamera& camera,
                                                       const ScaleModel& scale,
                                                       const TriangulationOptions& options);

// The world point of a matched pair: linear (DLT) triangulation, or the stereo point of the side
// whose stereo parallax beats the rays' parallax. nullopt when the point is behind either camera,
// fails the reprojection chi2 tests in either keyframe or its distances disagree with the
// keypoints' pyramid levels.
std::optional<Eigen::Vector3d> TriangulatePair(const Keyframe& a, int keypoint_a, const Keyframe& b,
                                               int keypoint_b, const StereoCamera& camera,
                                               const ScaleModel& scale,
                                               const TriangulationOptions& options);

// Triangulates the keyframe against its best covisible keyframes (call after UpdateConnections)
// and adds every accepted point with both observations. Returns the new point ids.
std::vector<int> TriangulateWithNeighbours(SparseMap& map, int keyframe_id,
                                           const StereoCamera& camera,
                                           const TriangulationOptions& options);

}  // namespace planeloc
