#include "planeloc/tracking/local_mapping.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <set>

namespace planeloc {
std::vector<int> CreateStereoPoints(SparseMap& map, int keyframe_id, const StereoCamera& camera,
                                    const OdometryOptions& options) {
  const Keyframe& kf = map.keyframe(keyframe_id);
  const double close_depth = options.close_depth_baselines * camera.baseline;
  const double far_depth = options.far_depth_baselines * camera.baseline;
  std::vector<std::pair<float, int>> by_depth;  // (depth, keypoint): nearest first
  int existing = 0;
  for (int i = 0; i < static_cast<int>(kf.map_point_ids.size()); ++i) {
    if (kf.map_point_ids[i] >= 0) {
      ++existing;
    } else if (kf.features.depth[i] > 0) {
      by_depth.emplace_back(kf.features.depth[i], i);
    }
  }
  std::sort(by_depth.begin(), by_depth.end());
  const Rigid3d world_from_cam = kf.cam_from_world.Inverse();
  std::vector<std::pair<Eigen::Vector3d, int>> to_add;
  for (const auto& [depth, i] : by_depth) {
    const bool wanted = depth < close_depth || depth < far_depth ||
                        existing + static_cast<int>(to_add.size()) < options.min_new_stereo_points;
    if (!wanted) break;
    const cv::KeyPoint& kp = kf.features.left.keypoints[i];
    to_add.emplace_back(world_from_cam * camera.Unproject(Eigen::Vector2d(kp.pt.x, kp.pt.y), depth),
                        i);
  }
  std::vector<int> ids;
  ids.reserve(to_add.size());
  for (const auto& [point, keypoint] : to_add)
    ids.push_back(map.AddPoint(point, keyframe_id, keypoint));
  return ids;
}

int CullRecentPoints(SparseMap& map, std::vector<int>& recent_point_ids, int current_keyframe_id,
                     const OdometryOptions& options) {
  int erased = 0;
  std::vector<int> kept;
  for (int id : recent_point_ids) {
    if (!map.HasPoint(id)) continue;
    const MapPoint& point = map.point(id);
    const int age = current_keyframe_id - point.first_keyframe_id;
    const int observers = static_cast<int>(point.observations.size());
    if (point.FoundRatio() < options.min_found_ratio ||
        (age >= 2 && observers < options.min_point_observations)) {
      map.ErasePoint(id);
      ++erased;
    } else if (age < 3) {
      kept.push_back(id);
    }
  }
  recent_point_ids = std::move(kept);
  return erased;
}

bool IsTurning(const SparseMap& map, int keyframe_id, const OdometryOptions& options) {
  const auto& keyframes = map.keyframes();
  auto it = keyframes.find(keyframe_id);
  if (it == keyframes.end()) return false;
  for (int back = 0; back < options.ba_window_keyframes && it != keyframes.begin(); ++back) --it;
  const double angle = RotationAngle(map.keyframe(keyframe_id).cam_from_world.rotation,
                                     it->second.cam_from_world.rotation);
  return angle > options.ba_turn_angle_deg * std::numbers::pi / 180.0;
}

WindowProblem BuildLocalWindow(const SparseMap& map, int keyframe_id,
                               const OdometryOptions& options) {
  const int window_size = IsTurning(map, keyframe_id, options) ? options.ba_window_keyframes_turn
                                                               : options.ba_window_keyframes;
  std::vector<int> local = map.BestCovisible(keyframe_id, window_size - 1);
  if (window_size > options.ba_window_keyframes) {
    // At a turn few keyframes share points with the new one; the window reaches further along
    // the covisibility graph (neighbours of neighbours, best first), which links the keyframes
    // before the corner to the ones after it through the ones in it.
    std::set<int> taken(local.begin(), local.end());
    taken.insert(keyframe_id);
    for (std::size_t k = 0; k < local.size() && static_cast<int>(local.size()) < window_size - 1;
         ++k) {
      for (const int neighbour : map.BestCovisible(local[k], window_size)) {
        if (static_cast<int>(local.size()) >= window_size - 1) break;
        if (taken.insert(neighbour).second) local.push_back(neighbour);
      }
    }
  }
  local.push_back(keyframe_id);
  std::sort(local.begin(), local.end());
  const std::set<int> local_set(local.begin(), local.end());

  std::set<int> point_ids;
  for (int kf_id : local) {
    for (int id : map.keyframe(kf_id).map_point_ids) {
      if (id >= 0) point_ids.insert(id);
    }
  }
  // Anchors: keyframes outside the window seeing its points, the most connected first.
  std::map<int, int> anchor_counts;
  for (int id : point_ids) {
    for (const auto& [kf_id, keypoint] : map.point(id).observations) {
      if (!local_set.count(kf_id)) ++anchor_counts[kf_id];
    }
  }
  std::vector<std::pair<int, int>> ranked;  // (-count, id)
  for (const auto& [kf_id, count] : anchor_counts) ranked.emplace_back(-count, kf_id);
  std::sort(ranked.begin(), ranked.end());
  std::set<int> fixed;
  for (const auto& [neg_count, kf_id] : ranked) {
    if (static_cast<int>(fixed.size()) >= options.ba_max_fixed_keyframes) break;
    fixed.insert(kf_id);
  }
  const int first_keyframe = options.ba_fix_first_keyframe ? map.keyframes().begin()->first : -1;
  const bool gauge_fixed =
      !fixed.empty() || local_set.count(first_keyframe) || !options.ba_fix_first_keyframe;

  WindowProblem problem;
  auto add_keyframe = [&](int kf_id, bool is_fixed) {
    problem.keyframes.push_back({kf_id, map.keyframe(kf_id).cam_from_world, is_fixed});
  };
  for (int kf_id : local) {
    add_keyframe(kf_id, kf_id == first_keyframe || (!gauge_fixed && kf_id == local.front()));
  }
  for (int kf_id : fixed) add_keyframe(kf_id, true);

  const double scale2 = map.scale().scale_factor * map.scale().scale_factor;
  for (int id : point_ids) {
    const MapPoint& point = map.point(id);
    problem.points.push_back(WindowPoint{id, point.point_in_world, std::nullopt});
    for (const auto& [kf_id, keypoint] : point.observations) {
      if (!local_set.count(kf_id) && !fixed.count(kf_id)) continue;
      const Keyframe& kf = map.keyframe(kf_id);
      const cv::KeyPoint& kp = kf.features.left.keypoints[keypoint];
      WindowObservation obs;
      obs.keyframe_id = kf_id;
      obs.point_id = id;
      obs.u_left = kp.pt.x;
      obs.v = kp.pt.y;
      obs.u_right = kf.features.u_right[keypoint];
      obs.information = 1.0 / std::pow(scale2, kp.octave);
      problem.observations.push_back(obs);
    }
  }
  return problem;
}

WindowSnapshot SnapshotWindow(const SparseMap& map, const WindowProblem& problem) {
  WindowSnapshot snapshot;
  for (const WindowKeyframe& kf : problem.keyframes) {
    snapshot.keyframe_versions.push_back(map.HasKeyframe(kf.id) ? map.keyframe(kf.id).version : 0);
  }
  for (const WindowPoint& p : problem.points) {
    snapshot.point_versions.push_back(map.HasPoint(p.id) ? map.point(p.id).version : 0);
  }
  return snapshot;
}

BaApplyStats ApplyWindowBa(SparseMap& map, const WindowProblem& problem,
                           const WindowBaResult& result, const StereoCamera& camera,
                           const WindowSnapshot* snapshot) {
  BaApplyStats stats;
  if (!result.usable) return stats;
  // Ids moved since the snapshot: their newer value stays.
  std::set<int> stale_keyframes, stale_points;
  if (snapshot) {
    for (std::size_t i = 0; i < problem.keyframes.size(); ++i) {
      const int id = problem.keyframes[i].id;
      if (map.HasKeyframe(id) && map.keyframe(id).version != snapshot->keyframe_versions.at(i)) {
        stale_keyframes.insert(id);
      }
    }
    for (std::size_t i = 0; i < problem.points.size(); ++i) {
      const int id = problem.points[i].id;
      if (map.HasPoint(id) && map.point(id).version != snapshot->point_versions.at(i)) {
        stale_points.insert(id);
      }
    }
  }
  for (const auto& [kf_id, pose] : result.cam_from_world) {
    if (!map.HasKeyframe(kf_id)) continue;
    if (stale_keyframes.count(kf_id)) {
      ++stats.stale_keyframes;
      continue;
    }
    map.SetKeyframePose(kf_id, pose);
    ++stats.keyframes;
  }
  for (const auto& [id, position] : result.point_in_world) {
    if (!map.HasPoint(id)) continue;
    if (stale_points.count(id)) {
      ++stats.stale_points;
      continue;
    }
    map.SetPointPosition(id, position);
    ++stats.points;
  }
  std::vector<double> errors;
  for (std::size_t i = 0; i < problem.observations.size(); ++i) {
    const WindowObservation& obs = problem.observations[i];
    if (!map.HasPoint(obs.point_id) || !map.HasKeyframe(obs.keyframe_id)) continue;
    const MapPoint& point = map.point(obs.point_id);
    if (!point.observations.count(obs.keyframe_id)) continue;
    if (stale_points.count(obs.point_id) || stale_keyframes.count(obs.keyframe_id)) continue;
    if (i < result.observation_inlier.size() && !result.observation_inlier[i]) {
      map.EraseObservation(obs.point_id, obs.keyframe_id);
      ++stats.removed_observations;
      continue;
    }
    // A point seen by one keyframe fits its stereo measurement exactly: not informative.
    if (point.observations.size() < 2) continue;
    const Eigen::Vector3d in_cam =
        map.keyframe(obs.keyframe_id).cam_from_world * point.point_in_world;
    const auto projected = camera.ProjectStereo(in_cam);
    if (!projected) continue;
    double e2 = std::pow((*projected)(0) - obs.u_left, 2) + std::pow((*projected)(1) - obs.v, 2);
    if (obs.u_right >= 0) e2 += std::pow((*projected)(2) - obs.u_right, 2);
    errors.push_back(std::sqrt(e2));
  }
  for (const auto& [id, position] : result.point_in_world) {
    if (map.HasPoint(id) && !stale_points.count(id)) map.UpdatePointGeometry(id);
  }
  if (!errors.empty()) {
    auto mid = errors.begin() + static_cast<std::ptrdiff_t>(errors.size() / 2);
    std::nth_element(errors.begin(), mid, errors.end());
    stats.median_reprojection_px = *mid;
  }
  return stats;
}

}  // namespace planeloc
