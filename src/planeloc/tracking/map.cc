#include "planeloc/tracking/map.h"

#include <algorithm>
#include <cmath>

#include "planeloc/features/orb_extractor.h"

namespace planeloc {

int ScaleModel::PredictLevel(double max_distance, double distance) const {
  if (distance <= 0) return 0;
  const double ratio = max_distance / distance;
  const int level = static_cast<int>(std::ceil(std::log(ratio) / std::log(scale_factor)));
  return std::clamp(level, 0, num_levels - 1);
}

int SparseMap::AddKeyframe(const Frame& frame) {
  Keyframe kf;
  kf.id = next_keyframe_id_++;
  kf.frame_id = frame.id;
  kf.timestamp = frame.timestamp;
  kf.cam_from_world = frame.cam_from_world;
  kf.features = frame.features;
  kf.features.left.pyramid.clear();
  kf.grid = frame.grid;
  kf.map_point_ids.assign(frame.features.left.keypoints.size(), -1);
  const int id = kf.id;
  keyframes_.emplace(id, std::move(kf));
  return id;
}

int SparseMap::AddPoint(const Eigen::Vector3d& point_in_world, int keyframe_id, int keypoint) {
  MapPoint point;
  point.id = next_point_id_++;
  point.point_in_world = point_in_world;
  point.first_keyframe_id = keyframe_id;
  point.reference_keyframe_id = keyframe_id;
  const int id = point.id;
  points_.emplace(id, std::move(point));
  AddObservation(id, keyframe_id, keypoint);
  UpdatePoint(id);
  return id;
}

void SparseMap::AddObservation(int point_id, int keyframe_id, int keypoint) {
  Keyframe& kf = keyframes_.at(keyframe_id);
  MapPoint& point = points_.at(point_id);
  if (kf.map_point_ids.at(keypoint) >= 0 || point.observations.count(keyframe_id) > 0) return;
  kf.map_point_ids[keypoint] = point_id;
  point.observations[keyframe_id] = keypoint;
}

void SparseMap::EraseObservation(int point_id, int keyframe_id) {
  MapPoint& point = points_.at(point_id);
  const auto it = point.observations.find(keyframe_id);
  if (it == point.observations.end()) return;
  keyframes_.at(keyframe_id).map_point_ids.at(it->second) = -1;
  point.observations.erase(it);
  if (point.observations.empty()) {
    points_.erase(point_id);
  } else if (point.reference_keyframe_id == keyframe_id) {
    point.reference_keyframe_id = point.observations.begin()->first;
  }
}

void SparseMap::ErasePoint(int point_id) {
  const auto it = points_.find(point_id);
  if (it == points_.end()) return;
  for (const auto& [kf_id, keypoint] : it->second.observations) {
    keyframes_.at(kf_id).map_point_ids.at(keypoint) = -1;
  }
  points_.erase(it);
}

std::vector<int> SparseMap::EraseKeyframe(int keyframe_id) {
  const auto it = keyframes_.find(keyframe_id);
  if (it == keyframes_.end()) return {};
  std::vector<int> erased;
  const std::vector<int> point_ids = it->second.map_point_ids;  // EraseObservation edits it
  for (const int point_id : point_ids) {
    if (point_id < 0 || !HasPoint(point_id)) continue;
    EraseObservation(point_id, keyframe_id);
    if (!HasPoint(point_id)) erased.push_back(point_id);
  }
  for (const auto& [other, weight] : it->second.covisibility) {
    const auto neighbour = keyframes_.find(other);
    if (neighbour != keyframes_.end()) neighbour->second.covisibility.erase(keyframe_id);
  }
  keyframes_.erase(it);
  return erased;
}

void SparseMap::ReplacePoint(int keep_id, int drop_id) {
  if (keep_id == drop_id || !HasPoint(keep_id) || !HasPoint(drop_id)) return;
  const auto drop_it = points_.find(drop_id);
  const MapPoint drop = std::move(drop_it->second);
  points_.erase(drop_it);
  MapPoint& keep = points_.at(keep_id);
  for (const auto& [kf_id, keypoint] : drop.observations) {
    Keyframe& kf = keyframes_.at(kf_id);
    if (keep.observations.count(kf_id) > 0) {
      kf.map_point_ids.at(keypoint) = -1;
    } else {
      kf.map_point_ids.at(keypoint) = keep_id;
      keep.observations[kf_id] = keypoint;
    }
  }
  keep.visible += drop.visible;
  keep.found += drop.found;
  keep.version = next_version_++;
  UpdatePoint(keep_id);
}

void SparseMap::UpdatePoint(int point_id) {
  MapPoint& point = points_.at(point_id);
  UpdateDescriptor(point);
  UpdateNormalAndDistances(point);
}

void SparseMap::UpdatePointGeometry(int point_id) {
  UpdateNormalAndDistances(points_.at(point_id));
}

void SparseMap::UpdateDescriptor(MapPoint& point) const {
  std::vector<cv::Mat> descriptors;
  for (const auto& [kf_id, keypoint] : point.observations) {
    descriptors.push_back(keyframes_.at(kf_id).features.left.descriptors.row(keypoint));
  }
  if (descriptors.empty()) return;
  const std::size_t n = descriptors.size();
  std::size_t best = 0;
  int best_median = 1 << 30;
  std::vector<int> distances(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = 0; j < n; ++j) {
      distances[j] = i == j ? 0 : DescriptorDistance(descriptors[i], descriptors[j]);
    }
    std::nth_element(distances.begin(), distances.begin() + (n - 1) / 2, distances.end());
    const int median = distances[(n - 1) / 2];
    if (median < best_median) {
      best_median = median;
      best = i;
    }
  }
  point.descriptor = descriptors[best].clone();
}

void SparseMap::UpdateNormalAndDistances(MapPoint& point) const {
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (const auto& [kf_id, keypoint] : point.observations) {
    const Eigen::Vector3d ray = point.point_in_world - keyframes_.at(kf_id).CameraCenter();
    if (ray.norm() > 0) normal += ray.normalized();
  }
  if (normal.norm() > 0) point.normal = normal.normalized();
  const Keyframe& ref = keyframes_.at(point.reference_keyframe_id);
  const auto obs = point.observations.find(ref.id);
  if (obs == point.observations.end()) return;
  const double distance = (point.point_in_world - ref.CameraCenter()).norm();
  const int level = ref.features.left.keypoints.at(obs->second).octave;
  point.max_distance = distance * std::pow(scale_.scale_factor, level);
  point.min_distance = point.max_distance / std::pow(scale_.scale_factor, scale_.num_levels - 1);
}

void SparseMap::UpdateConnections(int keyframe_id) {
  Keyframe& kf = keyframes_.at(keyframe_id);
  std::map<int, int> counts;
  for (int point_id : kf.map_point_ids) {
    if (point_id < 0) continue;
    for (const auto& [other, keypoint] : points_.at(point_id).observations) {
      if (other != keyframe_id) ++counts[other];
    }
  }
  for (const auto& [other, weight] : kf.covisibility) {
    if (counts.count(other) == 0 && keyframes_.count(other)) {
      keyframes_.at(other).covisibility.erase(keyframe_id);
    }
  }
  kf.covisibility = counts;
  for (const auto& [other, weight] : counts)
    keyframes_.at(other).covisibility[keyframe_id] = weight;
}

std::vector<int> SparseMap::BestCovisible(int keyframe_id, int n) const {
  std::vector<std::pair<int, int>> edges;  // (-weight, id): sorts by weight desc, id asc
  for (const auto& [other, weight] : keyframes_.at(keyframe_id).covisibility) {
    edges.emplace_back(-weight, other);
  }
  std::sort(edges.begin(), edges.end());
  std::vector<int> result;
  for (const auto& [neg_weight, id] : edges) {
    if (static_cast<int>(result.size()) >= n) break;
    result.push_back(id);
  }
  return result;
}

int SparseMap::NumTrackedPoints(int keyframe_id, int min_observations) const {
  int n = 0;
  for (int point_id : keyframes_.at(keyframe_id).map_point_ids) {
    if (point_id >= 0 &&
        static_cast<int>(points_.at(point_id).observations.size()) >= min_observations) {
      ++n;
    }
  }
  return n;
}

void SparseMap::SetKeyframePose(int id, const Rigid3d& cam_from_world) {
  Keyframe& keyframe = keyframes_.at(id);
  keyframe.cam_from_world = cam_from_world;
  keyframe.version = next_version_++;
}

void SparseMap::SetPointPosition(int id, const Eigen::Vector3d& point_in_world) {
  MapPoint& point = points_.at(id);
  point.point_in_world = point_in_world;
  point.version = next_version_++;
}

}  // namespace planeloc
