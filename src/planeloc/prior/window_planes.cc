#include "planeloc/prior/window_planes.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

namespace planeloc {

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

WindowPointEstimates EstimateWindowPoints(const WindowProblem& problem, const SparseMap& map,
                                          const StereoCamera& camera,
                                          const PlaneAssociationOptions& options) {
  WindowPointEstimates estimates;
  estimates.reserve(problem.points.size());
  for (const WindowPoint& p : problem.points) {
    estimates.push_back(VisualPointEstimate(map, map.point(p.id), camera, options));
  }
  return estimates;
}

void RecordWindow(const WindowProblem& problem, const WindowPointEstimates& estimates,
                  PlaneAssociator& planes) {
  // The newest keyframe of the window that observes each point: the keyframes whose pose error
  // the point's record carries most recently.
  std::map<int, int> newest_observer;
  for (const WindowObservation& observation : problem.observations) {
    int& newest = newest_observer.try_emplace(observation.point_id, -1).first->second;
    newest = std::max(newest, observation.keyframe_id);
  }
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    if (!estimates[i]) continue;
    const auto observer = newest_observer.find(problem.points[i].id);
    planes.Record(problem.points[i].id, *estimates[i],
                  observer == newest_observer.end() ? -1 : observer->second);
  }
}

int AssociateWindowPlanes(WindowProblem& problem, const WindowPointEstimates& estimates,
                          const PlaneAssociationOptions& options, const PlaneAssociator& planes) {
  int associations = 0;
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    if (!estimates[i]) continue;
    if (const auto association = planes.Associate(*estimates[i])) {
      WindowPoint& window_point = problem.points[i];
      window_point.plane_id = association->plane_id;
      window_point.plane_sigma = association->sigma;
      ++associations;
    }
  }
  // Staged activation: too few associations for the plane term to be trusted, plain BA.
  const bool active = associations >= options.min_associations;
  std::set<int> plane_ids;
  for (WindowPoint& p : problem.points) {
    if (!active) {
      p.plane_id.reset();
      p.plane_sigma = 0;
    } else if (p.plane_id) {
      plane_ids.insert(*p.plane_id);
    }
  }
  for (const int plane_id : plane_ids) {
    problem.planes.push_back(WindowPlane{plane_id, planes.plane(plane_id).plane_in_map});
  }
  return associations;
}

}  // namespace planeloc
