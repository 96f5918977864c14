#include "planeloc/tracking/matcher.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "planeloc/features/orb_extractor.h"

namespace planeloc {
namespace {

constexpr int kHistogramBins = 30;

// Indices of the (up to) three largest bins; second and third only when they hold at least a
// tenth of the largest (ORB-SLAM2 ComputeThreeMaxima).
std::array<int, 3> ThreeMaxima(const std::array<std::vector<int>, kHistogramBins>& histogram) {
  std::array<int, 3> best = {-1, -1, -1};
  std::array<std::size_t, 3> sizes = {0, 0, 0};
  for (int bin = 0; bin < kHistogramBins; ++bin) {
    const std::size_t s = histogram[bin].size();
    if (s > sizes[0]) {
      sizes = {s, sizes[0], sizes[1]};
      best = {bin, best[0], best[1]};
    } else if (s > sizes[1]) {
      sizes = {sizes[0], s, sizes[1]};
      best = {best[0], bin, best[1]};
    } else if (s > sizes[2]) {
      sizes[2] = s;
      best[2] = bin;
    }
  }
  if (sizes[1] < 0.1 * sizes[0]) best[1] = -1;
  if (sizes[2] < 0.1 * sizes[0]) best[2] = -1;
  return best;
}

}  // namespace

std::vector<ProjectionMatch> MatchByProjection(const std::vector<MatchSource>& sources,
                                               const Frame& frame, const StereoCamera& camera,
                                               const MatchOptions& options) {
  const int n = frame.size();
  std::vector<int> best_distance(n, options.max_distance + 1);
  std::vector<int> best_source(n, -1);
  const Eigen::Matrix3d rotation = frame.cam_from_world.RotationMatrix();
  const Eigen::Vector3d& translation = frame.cam_from_world.translation;
  for (int s = 0; s < static_cast<int>(sources.size()); ++s) {
    const MatchSource& source = sources[s];
    const Eigen::Vector3d in_cam = rotation * source.point_in_world + translation;
    if (in_cam.z() <= 0) continue;
    const double u = camera.fx * in_cam.x() / in_cam.z() + camera.cx;
    const double v = camera.fy * in_cam.y() / in_cam.z() + camera.cy;
    if (u < 0 || v < 0 || u >= camera.width || v >= camera.height) continue;
    const double u_right = u - camera.BaselineTimesFx() / in_cam.z();
    const std::vector<int> candidates = frame.grid.InArea(
        frame.features.left.keypoints, u, v, source.radius, source.min_level, source.max_level);
    int best = options.max_distance + 1, second = 1 << 20, best_index = -1;
    int best_level = -1, second_level = -1;
    for (int i : candidates) {
      if (frame.map_point_ids[i] >= 0) continue;
      if (options.check_right && frame.features.u_right[i] >= 0 &&
          std::abs(u_right - frame.features.u_right[i]) > source.radius) {
        continue;
      }
      const int d = DescriptorDistance(source.descriptor, frame.features.left.descriptors.row(i));
      if (d < best) {
        second = best;
        second_level = best_level;
        best = d;
        best_index = i;
        best_level = frame.keypoint(i).octave;
      } else if (d < second) {
        second = d;
        second_level = frame.keypoint(i).octave;
      }
    }
    if (best_index < 0 || best > options.max_distance) continue;
    // Ratio test only against a competitor on the same level (ORB-SLAM2 local-map search).
    if (options.ratio < 1.0 && (options.ratio_across_levels || best_level == second_level) &&
        best > options.ratio * second) {
      continue;
    }
    if (best < best_distance[best_index]) {
      best_distance[best_index] = best;
      best_source[best_index] = s;
    }
  }

  std::vector<ProjectionMatch> matches;
  for (int i = 0; i < n; ++i) {
    if (best_source[i] >= 0) matches.push_back({i, best_source[i], best_distance[i]});
  }
  if (!options.check_orientation) return matches;

  std::array<std::vector<int>, kHistogramBins> histogram;
  std::vector<bool> keep(matches.size(), true);
  for (int m = 0; m < static_cast<int>(matches.size()); ++m) {
    const double source_angle = sources[matches[m].source].angle;
    const double angle = frame.keypoint(matches[m].keypoint).angle;
    if (source_angle < 0 || angle < 0) continue;
    double rotation_deg = source_angle - angle;
    if (rotation_deg < 0) rotation_deg += 360.0;
    int bin = static_cast<int>(std::lround(rotation_deg * kHistogramBins / 360.0));
    if (bin == kHistogramBins) bin = 0;
    histogram[std::clamp(bin, 0, kHistogramBins - 1)].push_back(m);
  }
  const std::array<int, 3> maxima = ThreeMaxima(histogram);
  for (int bin = 0; bin < kHistogramBins; ++bin) {
    if (bin == maxima[0] || bin == maxima[1] || bin == maxima[2]) continue;
    for (int m : histogram[bin]) keep[m] = false;
  }
  std::vector<ProjectionMatch> kept;
  for (std::size_t m = 0; m < matches.size(); ++m) {
    if (keep[m]) kept.push_back(matches[m]);
  }
  return kept;
}

std::vector<MatchSource> SourcesFromFrame(const Frame& last, const StereoCamera& camera,
                                          const SparseMap& map, const Rigid3d& cam_from_world_pred,
                                          double radius, double scale_factor, double close_depth) {
  // Motion along the optical axis decides which pyramid levels the points reappear at.
  const Rigid3d current_from_last = cam_from_world_pred * last.cam_from_world.Inverse();
  const Eigen::Vector3d last_in_current = current_from_last.translation;
  const bool forward = -last_in_current.z() > camera.baseline;
  const bool backward = last_in_current.z() > camera.baseline;
  std::vector<MatchSource> sources;
  for (int i = 0; i < last.size(); ++i) {
    MatchSource source;
    if (last.map_point_ids[i] >= 0 && !last.outlier[i] && map.HasPoint(last.map_point_ids[i])) {
      source.map_point_id = last.map_point_ids[i];
      source.point_in_world = map.point(source.map_point_id).point_in_world;
    } else if (last.HasDepth(i) && last.features.depth[i] < close_depth) {
      source.point_in_world = last.UnprojectToWorld(i, camera);
    } else {
      continue;
    }
    const cv::KeyPoint& kp = last.keypoint(i);
    source.descriptor = last.descriptor(i);
    source.angle = kp.angle;
    source.radius = radius * std::pow(scale_factor, kp.octave);
    if (forward) {
      source.min_level = kp.octave;
    } else if (backward) {
      source.max_level = kp.octave;
    } else {
      source.min_level = std::max(0, kp.octave - 1);
      source.max_level = kp.octave + 1;
    }
    sources.push_back(std::move(source));
  }
  return sources;
}

std::vector<MatchSource> SourcesFromKeyframe(const Keyframe& keyframe, const SparseMap& map,
                                             double radius, double scale_factor) {
  std::vector<MatchSource> sources;
  for (int i = 0; i < static_cast<int>(keyframe.map_point_ids.size()); ++i) {
    const int id = keyframe.map_point_ids[i];
    if (id < 0 || !map.HasPoint(id)) continue;
    const cv::KeyPoint& kp = keyframe.features.left.keypoints[i];
    MatchSource source;
    source.map_point_id = id;
    source.point_in_world = map.point(id).point_in_world;
    source.descriptor = map.point(id).descriptor;
    source.angle = kp.angle;
    source.radius = radius * std::pow(scale_factor, kp.octave);
    source.min_level = std::max(0, kp.octave - 2);
    source.max_level = kp.octave + 2;
    sources.push_back(std::move(source));
  }
  return sources;
}

std::vector<MatchSource> SourcesFromLocalMap(const std::vector<int>& point_ids,
                                             const SparseMap& map, const Frame& frame,
                                             const StereoCamera& camera, double radius_factor,
                                             std::vector<int>* visible_point_ids) {
  const Eigen::Matrix3d rotation = frame.cam_from_world.RotationMatrix();
  const Eigen::Vector3d& translation = frame.cam_from_world.translation;
  const Eigen::Vector3d center = frame.CameraCenter();
  const ScaleModel& scale = map.scale();
  std::vector<MatchSource> sources;
  for (int id : point_ids) {
    const MapPoint& point = map.point(id);
    const Eigen::Vector3d in_cam = rotation * point.point_in_world + translation;
    if (in_cam.z() <= 0) continue;
    const double u = camera.fx * in_cam.x() / in_cam.z() + camera.cx;
    const double v = camera.fy * in_cam.y() / in_cam.z() + camera.cy;
    if (u < 0 || v < 0 || u >= camera.width || v >= camera.height) continue;
    const Eigen::Vector3d ray = point.point_in_world - center;
    const double distance = ray.norm();
    if (distance < 0.8 * point.min_distance || distance > 1.2 * point.max_distance) continue;
    const double view_cos = ray.dot(point.normal) / distance;
    if (view_cos < 0.5) continue;
    if (visible_point_ids) visible_point_ids->push_back(id);
    const int level = scale.PredictLevel(point.max_distance, distance);
    MatchSource source;
    source.map_point_id = id;
    source.point_in_world = point.point_in_world;
    source.descriptor = point.descriptor;
    source.radius =
        radius_factor * (view_cos > 0.998 ? 2.5 : 4.0) * std::pow(scale.scale_factor, level);
    source.min_level = std::max(0, level - 1);
    source.max_level = level;
    sources.push_back(std::move(source));
  }
  return sources;
}

}  // namespace planeloc
