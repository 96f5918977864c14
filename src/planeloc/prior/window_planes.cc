#include "planeloc/prior/window_planes.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <vector>

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

std::optional<PointEstimate> VisualPointEstimate(const SparseMap& map, const MapPoint& point,
                                                 const StereoCamera& camera,
                                                 const PlaneAssociationOptions& options) {
  std::vector<PointEstimate> estimates;
  for (const auto& [kf_id, keypoint] : point.observations) {
    const Keyframe& kf = map.keyframe(kf_id);
    const double u_right = kf.features.u_right[keypoint];
    if (u_right < 0) continue;
    const cv::KeyPoint& kp = kf.features.left.keypoints[keypoint];
    const double sigma = options.pixel_sigma * std::pow(map.scale().scale_factor, kp.octave);
    if (auto e = StereoPointEstimate(camera, kf.cam_from_world, kp.pt.x, kp.pt.y, u_right, sigma)) {
      estimates.push_back(*e);
    }
  }
  if (estimates.empty()) return std::nullopt;
  return FusePointEstimates(estimates);
}

void AssociateWindowPlanes(WindowProblem& problem, const SparseMap& map, const StereoCamera& camera,
                           const PlaneAssociationOptions& options, PlaneAssociator& planes) {
  // All of the window's points are recorded before any is associated: the records may move the
  // gate's centre (PlaneAssociator::FinishRecords, the trajectory's offset from the map).
  std::vector<std::optional<PointEstimate>> estimates;
  estimates.reserve(problem.points.size());
  for (const WindowPoint& p : problem.points) {
    estimates.push_back(VisualPointEstimate(map, map.point(p.id), camera, options));
    if (estimates.back()) planes.Record(p.id, *estimates.back());
  }
  planes.FinishRecords();

  int associations = 0;
  std::vector<double> map_variances;     // per problem point, of its association
  std::vector<double> common_variances;  // per problem point, of its association's plane
  std::map<int, int> plane_points;       // associations per plane in this window
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    WindowPoint& window_point = problem.points[i];
    double map_variance = 0, common_variance = 0;
    if (const auto& estimate = estimates[i]) {
      auto association = planes.Associate(*estimate);
      if (association && !planes.GateAllows(association->plane_id, estimate->point_in_map,
                                            KeypointViews(map, map.point(window_point.id)))) {
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
    map_variances.push_back(map_variance);
    common_variances.push_back(common_variance);
  }
  std::set<int> plane_ids;
  {
    planes.UpdateHealth(associations);
    // Staged activation: too few associations for the plane term to be trusted, plain BA.
    const bool active = associations >= options.min_associations;
    for (WindowPoint& p : problem.points) {
      if (!active) {
        p.plane_id.reset();
        p.plane_sigma = 0;
      } else if (p.plane_id) {
        plane_ids.insert(*p.plane_id);
      }
    }
    const bool correct = options.plane_correction;
    for (std::size_t i = 0; active && correct && i < problem.points.size(); ++i) {
      WindowPoint& p = problem.points[i];
      if (!p.plane_id) continue;
      // The map's part (rms, map sigma, bias) moves to the plane's correction prior; the
      // fitted rms stays with the point as well (the surface's roughness about its plane).
      const double rms = planes.plane(*p.plane_id).rms;
      const double point_variance = p.plane_sigma * p.plane_sigma - map_variances[i];
      p.plane_sigma = std::sqrt(std::max(point_variance, 0.0) + rms * rms);
    }
    const int common = correct ? 0 : options.common_mode_points;
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
    const MapPlane& plane = planes.plane(plane_id);
    WindowPlane window_plane{plane_id, plane.plane_in_map};
    if (options.plane_correction) {
      const double sigma = planes.PlaneSigma(plane_id);
      window_plane.offset_sigma = std::sqrt(std::max(sigma * sigma - plane.rms * plane.rms, 0.0));
      window_plane.tilt_sigma = options.correction_tilt_sigma_deg * std::numbers::pi / 180.0;
      window_plane.anchor = plane.centroid;
    }
    problem.planes.push_back(window_plane);
  }
}

}  // namespace planeloc
