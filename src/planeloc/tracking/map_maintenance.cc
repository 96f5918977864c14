#include "planeloc/tracking/map_maintenance.h"

#include <algorithm>
#include <cmath>

#include "planeloc/features/orb_extractor.h"
#include "planeloc/tracking/matcher.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

void Require(bool condition, const char* what) {
  if (!condition) throw OptionsError(std::string("MapMaintenanceOptions: ") + what);
}

// ORB-SLAM2's second-level neighbours in SearchInNeighbors.
constexpr int kSecondNeighbours = 5;
// Chi-square 95 % for 2 and 3 degrees of freedom (ORB-SLAM2 Fuse).
constexpr double kChi2Mono = 5.99;
constexpr double kChi2Stereo = 7.8;

}  // namespace

void MapMaintenanceOptions::Check() const {
  Require(cull_redundant_ratio > 0 && cull_redundant_ratio <= 1,
          "cull_redundant_ratio must be in (0, 1]");
  Require(cull_min_observers >= 1, "cull_min_observers must be >= 1");
  Require(cull_keep_newest >= 1, "cull_keep_newest must be >= 1");
  Require(fuse_neighbours >= 1, "fuse_neighbours must be >= 1");
  Require(fuse_radius > 0, "fuse_radius must be > 0");
  Require(keep_keyframes >= 0, "keep_keyframes must be >= 0 (0: keep all)");
}

std::vector<int> CullRedundantKeyframes(SparseMap& map, int keyframe_id, double close_depth,
                                        const MapMaintenanceOptions& options,
                                        const std::set<int>& keep) {
  std::vector<int> erased;
  if (!map.HasKeyframe(keyframe_id) || map.keyframes().empty()) return erased;
  const int first = map.keyframes().begin()->first;
  std::set<int> newest;
  for (auto it = map.keyframes().rbegin();
       it != map.keyframes().rend() && static_cast<int>(newest.size()) < options.cull_keep_newest;
       ++it) {
    newest.insert(it->first);
  }
  std::vector<int> candidates;
  for (const auto& [other, weight] : map.keyframe(keyframe_id).covisibility) {
    if (other != first && other != keyframe_id && !newest.count(other) && !keep.count(other)) {
      candidates.push_back(other);
    }
  }
  for (const int kf_id : candidates) {
    if (!map.HasKeyframe(kf_id)) continue;
    const Keyframe& kf = map.keyframe(kf_id);
    int points = 0, redundant = 0;
    for (int i = 0; i < static_cast<int>(kf.map_point_ids.size()); ++i) {
      const int id = kf.map_point_ids[i];
      if (id < 0 || !map.HasPoint(id)) continue;
      const float depth = kf.features.depth[i];
      if (depth <= 0 || depth > close_depth) continue;
      ++points;
      const MapPoint& point = map.point(id);
      if (static_cast<int>(point.observations.size()) <= options.cull_min_observers) continue;
      const int level = kf.features.left.keypoints[i].octave;
      int observers = 0;
      for (const auto& [other, keypoint] : point.observations) {
        if (other == kf_id) continue;
        if (map.keyframe(other).features.left.keypoints[keypoint].octave <= level + 1 &&
            ++observers >= options.cull_min_observers) {
          break;
        }
      }
      if (observers >= options.cull_min_observers) ++redundant;
    }
    if (points > 0 && redundant > options.cull_redundant_ratio * points) {
      map.EraseKeyframe(kf_id);
      erased.push_back(kf_id);
    }
  }
  return erased;
}

int FuseIntoKeyframe(SparseMap& map, int target_id, const std::vector<int>& point_ids,
                     const StereoCamera& camera, double radius, std::vector<int>* dropped) {
  const ScaleModel& scale = map.scale();
  int fused = 0;
  for (const int id : point_ids) {
    if (!map.HasPoint(id) || !map.HasKeyframe(target_id)) continue;
    const MapPoint& point = map.point(id);
    if (point.observations.count(target_id)) continue;
    const Keyframe& target = map.keyframe(target_id);
    const Eigen::Vector3d in_cam = target.cam_from_world * point.point_in_world;
    if (in_cam.z() <= 0) continue;
    const auto projected = camera.ProjectStereo(in_cam);
    if (!projected) continue;
    const double u = (*projected)(0), v = (*projected)(1), u_right = (*projected)(2);
    if (u < 0 || v < 0 || u >= camera.width || v >= camera.height) continue;
    const Eigen::Vector3d ray = point.point_in_world - target.CameraCenter();
    const double distance = ray.norm();
    if (distance < 0.8 * point.min_distance || distance > 1.2 * point.max_distance) continue;
    if (ray.dot(point.normal) < 0.5 * distance) continue;
    const int level = scale.PredictLevel(point.max_distance, distance);
    const std::vector<int> candidates = target.grid.InArea(
        target.features.left.keypoints, u, v, radius * std::pow(scale.scale_factor, level),
        std::max(0, level - 1), level);
    int best = kDescriptorThresholdLow + 1, best_index = -1;
    for (const int i : candidates) {
      const cv::KeyPoint& kp = target.features.left.keypoints[i];
      const double inverse_sigma2 = 1.0 / std::pow(scale.scale_factor, 2.0 * kp.octave);
      const double eu = u - kp.pt.x, ev = v - kp.pt.y;
      const float kp_right = target.features.u_right[i];
      if (kp_right >= 0) {
        const double er = u_right - kp_right;
        if ((eu * eu + ev * ev + er * er) * inverse_sigma2 > kChi2Stereo) continue;
      } else if ((eu * eu + ev * ev) * inverse_sigma2 > kChi2Mono) {
        continue;
      }
      const int d = DescriptorDistance(point.descriptor, target.features.left.descriptors.row(i));
      if (d < best) {
        best = d;
        best_index = i;
      }
    }
    if (best_index < 0) continue;
    const int existing = target.map_point_ids[best_index];
    if (existing >= 0 && map.HasPoint(existing)) {
      if (existing == id) continue;
      // ORB-SLAM2 keeps the better-established point: more observers, more constraints.
      const bool keep_existing =
          map.point(existing).observations.size() > point.observations.size();
      const int keep = keep_existing ? existing : id;
      const int drop = keep_existing ? id : existing;
      map.ReplacePoint(keep, drop);
      if (dropped) dropped->push_back(drop);
    } else {
      map.AddObservation(id, target_id, best_index);
    }
    ++fused;
  }
  return fused;
}

std::vector<int> FuseWithNeighbours(SparseMap& map, int keyframe_id, const StereoCamera& camera,
                                    const MapMaintenanceOptions& options) {
  std::vector<int> dropped;
  if (!map.HasKeyframe(keyframe_id)) return dropped;
  std::vector<int> targets = map.BestCovisible(keyframe_id, options.fuse_neighbours);
  std::set<int> taken(targets.begin(), targets.end());
  taken.insert(keyframe_id);
  const std::size_t first_level = targets.size();
  for (std::size_t k = 0; k < first_level; ++k) {
    for (const int second : map.BestCovisible(targets[k], kSecondNeighbours)) {
      if (taken.insert(second).second) targets.push_back(second);
    }
  }
  auto points_of = [&map](int kf_id) {
    std::vector<int> ids;
    if (!map.HasKeyframe(kf_id)) return ids;
    for (const int id : map.keyframe(kf_id).map_point_ids) {
      if (id >= 0 && map.HasPoint(id)) ids.push_back(id);
    }
    return ids;
  };
  for (const int target : targets) {
    FuseIntoKeyframe(map, target, points_of(keyframe_id), camera, options.fuse_radius, &dropped);
  }
  std::set<int> candidates;
  for (const int target : targets) {
    for (const int id : points_of(target)) candidates.insert(id);
  }
  FuseIntoKeyframe(map, keyframe_id, {candidates.begin(), candidates.end()}, camera,
                   options.fuse_radius, &dropped);
  for (const int id : points_of(keyframe_id)) map.UpdatePoint(id);
  map.UpdateConnections(keyframe_id);
  return dropped;
}

std::vector<int> ForgetOldKeyframes(SparseMap& map, const MapMaintenanceOptions& options,
                                    const std::set<int>& keep) {
  std::vector<int> erased;
  if (options.keep_keyframes <= 0 || map.keyframes().empty()) return erased;
  const int first = map.keyframes().begin()->first;
  int excess = static_cast<int>(map.keyframes().size()) - 1 - options.keep_keyframes;
  std::vector<int> oldest;
  for (auto it = std::next(map.keyframes().begin());
       it != map.keyframes().end() && static_cast<int>(oldest.size()) < excess; ++it) {
    if (it->first != first && !keep.count(it->first)) oldest.push_back(it->first);
  }
  for (const int id : oldest) {
    map.EraseKeyframe(id);
    erased.push_back(id);
  }
  return erased;
}

}  // namespace planeloc
