#include "planeloc/tracking/triangulation.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "planeloc/features/orb_extractor.h"

namespace planeloc {
namespace {

double LevelScale(const ScaleModel& scale, int octave) {
  return std::pow(scale.scale_factor, octave);
}

double LevelSigma2(const ScaleModel& scale, int octave) {
  const double s = LevelScale(scale, octave);
  return s * s;
}

Eigen::Matrix3d Skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Median depth of the keyframe's map points in its own camera frame (0 if it has none).
double MedianSceneDepth(const SparseMap& map, const Keyframe& kf) {
  std::vector<double> depths;
  for (int id : kf.map_point_ids) {
    if (id >= 0 && map.HasPoint(id))
      depths.push_back((kf.cam_from_world * map.point(id).point_in_world).z());
  }
  if (depths.empty()) return 0;
  auto mid = depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2);
  std::nth_element(depths.begin(), mid, depths.end());
  return *mid;
}

// Reprojection chi2 test of a world point against keypoint i of a keyframe (stereo when the
// keypoint has a right match).
bool ReprojectionOk(const Keyframe& kf, int i, const Eigen::Vector3d& point_in_world,
                    const StereoCamera& camera, const ScaleModel& scale,
                    const TriangulationOptions& options) {
  const Eigen::Vector3d in_cam = kf.cam_from_world * point_in_world;
  if (in_cam.z() <= 0) return false;
  const auto projected = camera.ProjectStereo(in_cam);
  if (!projected) return false;
  const cv::KeyPoint& kp = kf.features.left.keypoints[i];
  const double sigma2 = LevelSigma2(scale, kp.octave);
  double e2 = std::pow((*projected)(0) - kp.pt.x, 2) + std::pow((*projected)(1) - kp.pt.y, 2);
  const float u_right = kf.features.u_right[i];
  if (u_right >= 0) {
    e2 += std::pow((*projected)(2) - u_right, 2);
    return e2 <= options.stereo_chi2 * sigma2;
  }
  return e2 <= options.mono_chi2 * sigma2;
}

// The free keypoints (no map point) of a keyframe in square cells, with their squared epipolar
// tolerance (chi2 * sigma^2 of the level).
class EpipolarGrid {
 public:
  static constexpr double kCell = 32;  // pixels

  EpipolarGrid(const Keyframe& kf, const StereoCamera& camera, const ScaleModel& scale, double chi2)
      : keypoints_(kf.features.left.keypoints),
        cols_(std::max(1, static_cast<int>(std::ceil(camera.width / kCell)))),
        rows_(std::max(1, static_cast<int>(std::ceil(camera.height / kCell)))),
        cells_(static_cast<std::size_t>(cols_ * rows_)),
        tolerance2_(keypoints_.size(), 0) {
    for (int j = 0; j < static_cast<int>(keypoints_.size()); ++j) {
      if (kf.map_point_ids[j] >= 0) continue;
      const int c = std::clamp(static_cast<int>(keypoints_[j].pt.x / kCell), 0, cols_ - 1);
      const int r = std::clamp(static_cast<int>(keypoints_[j].pt.y / kCell), 0, rows_ - 1);
      cells_[r * cols_ + c].push_back(j);
      tolerance2_[j] = chi2 * LevelSigma2(scale, keypoints_[j].octave);
      margin_ = std::max(margin_, std::sqrt(tolerance2_[j]) + 1);
    }
  }

  double tolerance2(int j) const { return tolerance2_[j]; }

  // Keypoints in the cells within margin of the line l = (a, b, c): a x + b y + c = 0, walking
  // along its major axis one cell at a time.
  void AlongLine(const Eigen::Vector3d& l, std::vector<int>& out) const {
    out.clear();
    const bool by_column = std::abs(l.y()) >= std::abs(l.x());
    const int steps = by_column ? cols_ : rows_;
    const int span = by_column ? rows_ : cols_;
    // Along the major axis s, the minor coordinate is m(s) = -(l_s s + c) / l_m; the margin
    // perpendicular to the line is at most margin / cos(angle) along the minor axis.
    const double l_s = by_column ? l.x() : l.y(), l_m = by_column ? l.y() : l.x();
    const double minor_margin = margin_ * std::hypot(l.x(), l.y()) / std::abs(l_m);
    for (int k = 0; k < steps; ++k) {
      const double m0 = -(l_s * k * kCell + l.z()) / l_m;
      const double m1 = -(l_s * (k + 1) * kCell + l.z()) / l_m;
      const int lo =
          std::max(0, static_cast<int>(std::floor((std::min(m0, m1) - minor_margin) / kCell)));
      const int hi = std::min(
          span - 1, static_cast<int>(std::floor((std::max(m0, m1) + minor_margin) / kCell)));
      for (int q = lo; q <= hi; ++q) {
        const auto& cell = by_column ? cells_[q * cols_ + k] : cells_[k * cols_ + q];
        out.insert(out.end(), cell.begin(), cell.end());
      }
    }
  }

 private:
  const std::vector<cv::KeyPoint>& keypoints_;
  int cols_, rows_;
  std::vector<std::vector<int>> cells_;
  std::vector<double> tolerance2_;
  double margin_ = 1;
};

}  // namespace

std::vector<std::pair<int, int>> MatchForTriangulation(const Keyframe& a, const Keyframe& b,
                                                       const StereoCamera& camera,
                                                       const ScaleModel& scale,
                                                       const TriangulationOptions& options) {
  // Fundamental matrix of b's image given a's pixel: x_b^T F x_a = 0.
  const Rigid3d b_from_a = b.cam_from_world * a.cam_from_world.Inverse();
  const Eigen::Matrix3d k_inv = camera.K().inverse();
  const Eigen::Matrix3d fundamental =
      k_inv.transpose() * Skew(b_from_a.translation) * b_from_a.RotationMatrix() * k_inv;
  // Epipole of a's centre in b (used to reject mono pairs too close to it, as ORB-SLAM2).
  const auto epipole = camera.Project(b_from_a.translation);

  const auto& kps_a = a.features.left.keypoints;
  const auto& kps_b = b.features.left.keypoints;
  // b's free keypoints bucketed by image cell, so that each epipolar line visits only the cells
  // it crosses (a brute-force scan cost ~200 ms per keyframe).
  const EpipolarGrid grid(b, camera, scale, options.epipolar_chi2);
  // best match in a per keypoint of b: (distance, keypoint in a)
  std::vector<std::pair<int, int>> best_for_b(kps_b.size(), {std::numeric_limits<int>::max(), -1});
  std::vector<int> candidates;
  for (int i = 0; i < static_cast<int>(kps_a.size()); ++i) {
    if (a.map_point_ids[i] >= 0) continue;
    const Eigen::Vector3d line = fundamental * Eigen::Vector3d(kps_a[i].pt.x, kps_a[i].pt.y, 1);
    const double norm2 = line.head<2>().squaredNorm();
    if (norm2 <= 0) continue;
    grid.AlongLine(line, candidates);
    const bool stereo_a = a.features.u_right[i] >= 0;
    const uint8_t* desc_a = a.features.left.descriptors.ptr<uint8_t>(i);
    int best = std::numeric_limits<int>::max(), second = best, best_j = -1;
    for (int j : candidates) {
      const cv::KeyPoint& kp = kps_b[j];
      const double d = line.x() * kp.pt.x + line.y() * kp.pt.y + line.z();
      if (d * d > grid.tolerance2(j) * norm2) continue;
      const int distance = DescriptorDistance(desc_a, b.features.left.descriptors.ptr<uint8_t>(j));
      if (distance > options.max_descriptor_distance) continue;
      if (!stereo_a && b.features.u_right[j] < 0 && epipole) {
        const double ex = epipole->x() - kp.pt.x, ey = epipole->y() - kp.pt.y;
        if (ex * ex + ey * ey < 100 * LevelScale(scale, kp.octave)) continue;
      }
      if (distance < best) {
        second = best;
        best = distance;
        best_j = j;
      } else if (distance < second) {
        second = distance;
      }
    }
    if (best_j < 0) continue;
    if (second != std::numeric_limits<int>::max() && best >= options.ratio * second) continue;
    if (best < best_for_b[best_j].first) best_for_b[best_j] = {best, i};
  }
  std::vector<std::pair<int, int>> matches;
  for (int j = 0; j < static_cast<int>(best_for_b.size()); ++j) {
    if (best_for_b[j].second >= 0) matches.emplace_back(best_for_b[j].second, j);
  }
  std::sort(matches.begin(), matches.end());
  return matches;
}

std::optional<Eigen::Vector3d> TriangulatePair(const Keyframe& a, int keypoint_a, const Keyframe& b,
                                               int keypoint_b, const StereoCamera& camera,
                                               const ScaleModel& scale,
                                               const TriangulationOptions& options) {
  const cv::KeyPoint& kp_a = a.features.left.keypoints[keypoint_a];
  const cv::KeyPoint& kp_b = b.features.left.keypoints[keypoint_b];
  const Eigen::Matrix3d k_inv = camera.K().inverse();
  const Eigen::Vector3d xn_a = k_inv * Eigen::Vector3d(kp_a.pt.x, kp_a.pt.y, 1);
  const Eigen::Vector3d xn_b = k_inv * Eigen::Vector3d(kp_b.pt.x, kp_b.pt.y, 1);
  const Rigid3d world_from_a = a.cam_from_world.Inverse();
  const Rigid3d world_from_b = b.cam_from_world.Inverse();
  const Eigen::Vector3d ray_a = world_from_a.rotation * xn_a;
  const Eigen::Vector3d ray_b = world_from_b.rotation * xn_b;
  const double cos_rays = ray_a.dot(ray_b) / (ray_a.norm() * ray_b.norm());

  // Parallax of the stereo pair (2 = no stereo): the better-conditioned measurement wins.
  const float depth_a = a.features.depth[keypoint_a], depth_b = b.features.depth[keypoint_b];
  const double cos_stereo_a =
      depth_a > 0 ? std::cos(2 * std::atan2(camera.baseline / 2, depth_a)) : 2;
  const double cos_stereo_b =
      depth_b > 0 ? std::cos(2 * std::atan2(camera.baseline / 2, depth_b)) : 2;
  const double cos_stereo = std::min(cos_stereo_a, cos_stereo_b);

  Eigen::Vector3d point;
  if (cos_rays < cos_stereo && cos_rays > 0 && (depth_a > 0 || depth_b > 0 || cos_rays < 0.9998)) {
    Eigen::Matrix<double, 3, 4> pa, pb;
    pa << a.cam_from_world.RotationMatrix(), a.cam_from_world.translation;
    pb << b.cam_from_world.RotationMatrix(), b.cam_from_world.translation;
    Eigen::Matrix4d design;
    design.row(0) = xn_a.x() * pa.row(2) - pa.row(0);
    design.row(1) = xn_a.y() * pa.row(2) - pa.row(1);
    design.row(2) = xn_b.x() * pb.row(2) - pb.row(0);
    design.row(3) = xn_b.y() * pb.row(2) - pb.row(1);
    const Eigen::JacobiSVD<Eigen::Matrix4d> svd(design, Eigen::ComputeFullV);
    const Eigen::Vector4d h = svd.matrixV().col(3);
    if (std::abs(h(3)) < 1e-12) return std::nullopt;
    point = h.head<3>() / h(3);
  } else if (depth_a > 0 && cos_stereo_a < cos_stereo_b) {
    point = world_from_a * camera.Unproject(Eigen::Vector2d(kp_a.pt.x, kp_a.pt.y), depth_a);
  } else if (depth_b > 0 && cos_stereo_b < cos_stereo_a) {
    point = world_from_b * camera.Unproject(Eigen::Vector2d(kp_b.pt.x, kp_b.pt.y), depth_b);
  } else {
    return std::nullopt;  // low parallax and no stereo
  }
  if (!point.allFinite()) return std::nullopt;
  if (!ReprojectionOk(a, keypoint_a, point, camera, scale, options) ||
      !ReprojectionOk(b, keypoint_b, point, camera, scale, options)) {
    return std::nullopt;
  }
  // Scale consistency: distances must scale like the keypoints' pyramid levels.
  const double dist_a = (point - world_from_a.translation).norm();
  const double dist_b = (point - world_from_b.translation).norm();
  if (dist_a <= 0 || dist_b <= 0) return std::nullopt;
  const double ratio_dist = dist_a / dist_b;
  const double ratio_octave = LevelScale(scale, kp_a.octave) / LevelScale(scale, kp_b.octave);
  const double ratio_factor = options.scale_ratio_slack * scale.scale_factor;
  if (ratio_dist * ratio_factor < ratio_octave || ratio_dist > ratio_octave * ratio_factor) {
    return std::nullopt;
  }
  return point;
}

std::vector<int> TriangulateWithNeighbours(SparseMap& map, int keyframe_id,
                                           const StereoCamera& camera,
                                           const TriangulationOptions& options) {
  std::vector<int> created;
  for (int neighbour_id : map.BestCovisible(keyframe_id, options.num_neighbours)) {
    const Keyframe& kf = map.keyframe(keyframe_id);
    const Keyframe& neighbour = map.keyframe(neighbour_id);
    // Too short a baseline: the pair adds nothing over stereo (ORB-SLAM2 stereo: < b) and
    // its rays are nearly parallel (ORB-SLAM2 monocular: < 1 % of the scene depth).
    const double baseline = (kf.CameraCenter() - neighbour.CameraCenter()).norm();
    if (baseline < camera.baseline) continue;
    const double median_depth = MedianSceneDepth(map, neighbour);
    if (median_depth <= 0 || baseline / median_depth < options.min_baseline_depth_ratio) continue;

    const auto matches = MatchForTriangulation(kf, neighbour, camera, map.scale(), options);
    std::vector<std::pair<Eigen::Vector3d, std::pair<int, int>>> accepted;
    for (const auto& [i, j] : matches) {
      const auto point = TriangulatePair(kf, i, neighbour, j, camera, map.scale(), options);
      if (point) accepted.push_back({*point, {i, j}});
    }
    for (const auto& [point, pair] : accepted) {
      const int id = map.AddPoint(point, keyframe_id, pair.first);
      map.AddObservation(id, neighbour_id, pair.second);
      map.UpdatePoint(id);
      created.push_back(id);
    }
  }
  return created;
}

}  // namespace planeloc
