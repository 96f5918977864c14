#include "planeloc/tracking/local_mapping.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>
#include <set>

namespace planeloc {
namespace {

// The point's keypoints in the keyframes observing it, for the crease gate.
std::vector<PlaneAssociator::KeypointView> KeypointViews(const SparseMap& map,
                                                         const MapPoint& point) {
  std::vector<PlaneAssociator::KeypointView> views;
  for (const auto& [kf_id, keypoint] : point.observations) {
    const cv::KeyPoint& kp = map.keyframe(kf_id).features.left.keypoints[keypoint];
    views.push_back({kf_id, Eigen::Vector2d(kp.pt.x, kp.pt.y)});
  }
  return views;
}

}  // namespace

std::vector<int> CreateStereoPoints(SparseMap& map, int keyframe_id, const StereoCamera& camera,
                                    const TrackerOptions& options) {
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
                     const TrackerOptions& options) {
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

bool IsTurning(const SparseMap& map, int keyframe_id, const TrackerOptions& options) {
  const auto& keyframes = map.keyframes();
  auto it = keyframes.find(keyframe_id);
  if (it == keyframes.end()) return false;
  for (int back = 0; back < options.ba_window_keyframes && it != keyframes.begin(); ++back) --it;
  const double angle = RotationAngle(map.keyframe(keyframe_id).cam_from_world.rotation,
                                     it->second.cam_from_world.rotation);
  return angle > options.ba_turn_angle_deg * std::numbers::pi / 180.0;
}

std::optional<PointEstimate> VisualPointEstimate(const SparseMap& map, const MapPoint& point,
                                                 const StereoCamera& camera,
                                                 const TrackerOptions& options) {
  std::vector<PointEstimate> estimates;
  for (const auto& [kf_id, keypoint] : point.observations) {
    const Keyframe& kf = map.keyframe(kf_id);
    const double u_right = kf.features.u_right[keypoint];
    if (u_right < 0) continue;
    const cv::KeyPoint& kp = kf.features.left.keypoints[keypoint];
    const double sigma = options.planes.pixel_sigma * std::pow(map.scale().scale_factor, kp.octave);
    if (auto e = StereoPointEstimate(camera, kf.cam_from_world, kp.pt.x, kp.pt.y, u_right, sigma)) {
      estimates.push_back(*e);
    }
  }
  if (estimates.empty()) return std::nullopt;
  return FusePointEstimates(estimates);
}

WindowProblem BuildLocalWindow(const SparseMap& map, int keyframe_id, const TrackerOptions& options,
                               const StereoCamera& camera, PlaneAssociator* planes) {
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
  std::set<int> plane_ids;
  int associations = 0;
  std::vector<double> map_variances;     // per problem point, of its association
  std::vector<double> common_variances;  // per problem point, of its association's plane
  std::map<int, int> plane_points;       // associations per plane in this window
  // Decided from the points' stereo measurements, not from their BA positions (hysteresis). All
  // of the window's points are recorded before any is associated: the records may move the
  // gate's centre (PlaneAssociator::FinishRecords, the trajectory's offset from the map).
  std::vector<std::optional<PointEstimate>> estimates;
  if (planes) {
    estimates.reserve(point_ids.size());
    for (int id : point_ids) {
      estimates.push_back(VisualPointEstimate(map, map.point(id), camera, options));
      if (estimates.back()) planes->Record(id, *estimates.back());
    }
    planes->FinishRecords();
  }
  std::size_t point_index = 0;
  for (int id : point_ids) {
    const MapPoint& point = map.point(id);
    WindowPoint window_point{id, point.point_in_world, std::nullopt};
    double map_variance = 0, common_variance = 0;
    if (planes) {
      if (const auto& estimate = estimates[point_index++]) {
        auto association = planes->Associate(*estimate);
        if (association && !planes->GateAllows(association->plane_id, estimate->point_in_map,
                                               KeypointViews(map, point))) {
          association.reset();  // across a confirmed crease, or outside the plane's image region
        }
        if (association) {
          window_point.plane_id = association->plane_id;
          window_point.plane_sigma = association->sigma;
          ++associations;
          ++plane_points[association->plane_id];
          map_variance = association->map_variance;
          common_variance = association->common_variance;
        }
      }
    }
    problem.points.push_back(window_point);
    map_variances.push_back(map_variance);
    common_variances.push_back(common_variance);
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
  if (planes) {
    planes->UpdateHealth(associations);
    // Staged activation: too few associations for the plane term to be trusted, plain BA.
    const bool active = associations >= options.planes.min_associations;
    for (WindowPoint& p : problem.points) {
      if (!active) {
        p.plane_id.reset();
        p.plane_sigma = 0;
      } else if (p.plane_id) {
        plane_ids.insert(*p.plane_id);
      }
    }
    const bool correct = options.planes.plane_correction;
    for (std::size_t i = 0; active && correct && i < problem.points.size(); ++i) {
      WindowPoint& p = problem.points[i];
      if (!p.plane_id) continue;
      // The map's part (rms, map sigma, bias) moves to the plane's correction prior; the
      // fitted rms stays with the point as well (the surface's roughness about its plane).
      const double rms = planes->plane(*p.plane_id).rms;
      const double point_variance = p.plane_sigma * p.plane_sigma - map_variances[i];
      p.plane_sigma = std::sqrt(std::max(point_variance, 0.0) + rms * rms);
    }
    const int common = correct ? 0 : options.planes.common_mode_points;
    for (std::size_t i = 0; active && common > 0 && i < problem.points.size(); ++i) {
      WindowPoint& p = problem.points[i];
      if (!p.plane_id) continue;
      const double n = plane_points[*p.plane_id];
      if (n <= common) continue;
      // sigma^2 = point variance + map variance: only the map's part is common to the plane.
      const double map_variance = map_variances[i];
      const double point_variance = p.plane_sigma * p.plane_sigma - map_variance;
      p.plane_sigma = std::sqrt(point_variance + map_variance * n / common);
    }
    // Planes.biasCommonMode: N_k points share the plane's bias b, N_k b^2 each (the marginal of
    // one shared offset); common_variance is 0 with the option off.
    for (std::size_t i = 0; active && i < problem.points.size(); ++i) {
      WindowPoint& p = problem.points[i];
      if (!p.plane_id || common_variances[i] <= 0.0) continue;
      const double n = plane_points[*p.plane_id];
      p.plane_sigma = std::sqrt(p.plane_sigma * p.plane_sigma + n * common_variances[i]);
    }
  }
  for (const int plane_id : plane_ids) {
    const MapPlane& plane = planes->plane(plane_id);
    WindowPlane window_plane{plane_id, plane.plane_in_map};
    if (options.planes.plane_correction) {
      const double sigma = planes->PlaneSigma(plane_id);
      window_plane.offset_sigma = std::sqrt(std::max(sigma * sigma - plane.rms * plane.rms, 0.0));
      window_plane.tilt_sigma = options.planes.correction_tilt_sigma_deg * std::numbers::pi / 180.0;
      window_plane.anchor = plane.centroid;
    }
    problem.planes.push_back(window_plane);
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
