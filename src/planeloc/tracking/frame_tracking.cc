#include "planeloc/tracking/frame_tracking.h"

#include <algorithm>
#include <map>
#include <set>

#include "planeloc/optim/pose_optimizer.h"
#include "planeloc/tracking/matcher.h"

namespace planeloc {

bool TrackWithMotionModel(const TrackingContext& context, const SparseMap& map, const Frame& last,
                          const Rigid3d& predicted, Frame& frame) {
  const OdometryOptions& options = context.options;
  MatchOptions match_options;
  match_options.check_orientation = true;
  std::vector<MatchSource> sources;
  std::vector<ProjectionMatch> matches;
  frame.cam_from_world = predicted;
  for (double factor : {1.0, 2.0}) {
    sources = SourcesFromFrame(last, context.camera, map, predicted,
                               factor * options.motion_search_radius, options.orb.scale_factor,
                               options.close_depth_baselines * context.camera.baseline);
    matches = MatchByProjection(sources, frame, context.camera, match_options);
    if (static_cast<int>(matches.size()) >= options.min_motion_matches) break;
  }
  if (static_cast<int>(matches.size()) < options.min_motion_matches) return false;

  // Pose from map points and the last frame's temporary stereo points together.
  std::vector<PoseObservation> observations;
  for (const ProjectionMatch& m : matches) {
    const cv::KeyPoint& kp = frame.keypoint(m.keypoint);
    observations.push_back({sources[m.source].point_in_world, kp.pt.x, kp.pt.y,
                            frame.features.u_right[m.keypoint],
                            context.extractor.InverseLevelSigma2(kp.octave)});
  }
  const PoseOptimizerResult result =
      OptimizePose(context.camera, predicted, observations, context.options.pose);
  if (result.num_inliers < 10) return false;
  frame.cam_from_world = result.cam_from_world;
  for (std::size_t k = 0; k < matches.size(); ++k) {
    const int id = sources[matches[k].source].map_point_id;
    if (id >= 0 && result.inlier[k]) frame.map_point_ids[matches[k].keypoint] = id;
  }
  return true;
}

bool TrackWithReferenceKeyframe(const TrackingContext& context, const SparseMap& map,
                                int reference_keyframe_id, const Frame& last, bool has_velocity,
                                const Rigid3d& predicted, Frame& frame) {
  const OdometryOptions& options = context.options;
  if (!map.HasKeyframe(reference_keyframe_id)) return false;
  std::fill(frame.map_point_ids.begin(), frame.map_point_ids.end(), -1);
  const Keyframe& reference = map.keyframe(reference_keyframe_id);
  // A wide window around the prediction, then around the last pose (the motion changed), then
  // the whole image with a strict ratio test. Without a velocity yet (second frame) the
  // prediction is "no motion", often metres off: only the whole-image search is reliable.
  struct Stage {
    double radius;
    Rigid3d pose;
    double ratio;
  };
  constexpr double kWholeImage = 4000.0;
  std::vector<Stage> stages;
  if (has_velocity) {
    stages.push_back({25.0, predicted, 0.9});
    stages.push_back({60.0, last.cam_from_world, 0.9});
  }
  stages.push_back({kWholeImage, last.cam_from_world, 0.8});
  for (const Stage& stage : stages) {
    MatchOptions match_options;
    match_options.check_orientation = true;
    match_options.ratio = stage.ratio;
    match_options.ratio_across_levels = stage.radius >= kWholeImage;
    match_options.check_right = stage.radius < kWholeImage;
    frame.cam_from_world = stage.pose;
    const std::vector<MatchSource> sources =
        SourcesFromKeyframe(reference, map, stage.radius, options.orb.scale_factor);
    const std::vector<ProjectionMatch> matches =
        MatchByProjection(sources, frame, context.camera, match_options);
    if (static_cast<int>(matches.size()) < 15) continue;
    for (const ProjectionMatch& m : matches) {
      frame.map_point_ids[m.keypoint] = sources[m.source].map_point_id;
    }
    std::fill(frame.outlier.begin(), frame.outlier.end(), false);
    if (OptimizeFramePose(context, map, frame) >= 10) return true;
    std::fill(frame.map_point_ids.begin(), frame.map_point_ids.end(), -1);
  }
  return false;
}

int OptimizeFramePose(const TrackingContext& context, const SparseMap& map, Frame& frame) {
  std::vector<PoseObservation> observations;
  std::vector<int> keypoints;
  for (int i = 0; i < frame.size(); ++i) {
    const int id = frame.map_point_ids[i];
    if (id < 0 || !map.HasPoint(id)) {
      frame.map_point_ids[i] = -1;
      continue;
    }
    const cv::KeyPoint& kp = frame.keypoint(i);
    observations.push_back({map.point(id).point_in_world, kp.pt.x, kp.pt.y,
                            frame.features.u_right[i],
                            context.extractor.InverseLevelSigma2(kp.octave)});
    keypoints.push_back(i);
  }
  if (observations.size() < 3) return 0;
  const PoseOptimizerResult result =
      OptimizePose(context.camera, frame.cam_from_world, observations, context.options.pose);
  frame.cam_from_world = result.cam_from_world;
  for (std::size_t k = 0; k < keypoints.size(); ++k)
    frame.outlier[keypoints[k]] = !result.inlier[k];
  return result.num_inliers;
}

std::vector<int> LocalPointIds(const TrackingContext& context, const SparseMap& map,
                               const Frame& frame, int& reference_keyframe_id) {
  const OdometryOptions& options = context.options;
  // Keyframes sharing points with the frame, by shared count, then their covisible neighbours.
  std::map<int, int> counts;
  for (int i = 0; i < frame.size(); ++i) {
    const int id = frame.map_point_ids[i];
    if (id < 0 || frame.outlier[i] || !map.HasPoint(id)) continue;
    for (const auto& [kf_id, keypoint] : map.point(id).observations) ++counts[kf_id];
  }
  std::vector<std::pair<int, int>> ranked;  // (-count, id)
  for (const auto& [kf_id, count] : counts) ranked.emplace_back(-count, kf_id);
  std::sort(ranked.begin(), ranked.end());
  if (!ranked.empty()) reference_keyframe_id = ranked.front().second;
  std::set<int> local;
  for (const auto& [neg, kf_id] : ranked) {
    if (static_cast<int>(local.size()) >= options.max_local_keyframes) break;
    local.insert(kf_id);
  }
  for (const auto& [neg, kf_id] : ranked) {
    if (static_cast<int>(local.size()) >= options.max_local_keyframes) break;
    for (int neighbour : map.BestCovisible(kf_id, 10)) local.insert(neighbour);
  }
  if (map.HasKeyframe(reference_keyframe_id)) local.insert(reference_keyframe_id);
  std::set<int> point_ids;
  for (int kf_id : local) {
    for (int id : map.keyframe(kf_id).map_point_ids) {
      if (id >= 0) point_ids.insert(id);
    }
  }
  for (int id : frame.map_point_ids) {
    if (id >= 0) point_ids.erase(id);
  }
  return {point_ids.begin(), point_ids.end()};
}

int TrackLocalMap(const TrackingContext& context, SparseMap& map, Frame& frame,
                  int& reference_keyframe_id) {
  const OdometryOptions& options = context.options;
  // Points already matched count as seen in this frame.
  for (int i = 0; i < frame.size(); ++i) {
    const int id = frame.map_point_ids[i];
    if (id >= 0 && map.HasPoint(id)) ++map.mutable_point(id).visible;
  }
  const std::vector<int> local_ids = LocalPointIds(context, map, frame, reference_keyframe_id);
  std::vector<int> visible;
  const std::vector<MatchSource> sources = SourcesFromLocalMap(
      local_ids, map, frame, context.camera, options.local_search_radius, &visible);
  for (int id : visible) ++map.mutable_point(id).visible;
  MatchOptions match_options;
  match_options.ratio = 0.8;
  for (const ProjectionMatch& m :
       MatchByProjection(sources, frame, context.camera, match_options)) {
    frame.map_point_ids[m.keypoint] = sources[m.source].map_point_id;
  }
  std::fill(frame.outlier.begin(), frame.outlier.end(), false);
  const int inliers = OptimizeFramePose(context, map, frame);
  for (int i = 0; i < frame.size(); ++i) {
    const int id = frame.map_point_ids[i];
    if (id >= 0 && !frame.outlier[i]) ++map.mutable_point(id).found;
  }
  return inliers;
}

}  // namespace planeloc
