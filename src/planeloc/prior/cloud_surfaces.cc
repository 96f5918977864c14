#include "planeloc/prior/cloud_surfaces.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "planeloc/util/error.h"

namespace planeloc {

namespace {

std::vector<Eigen::Vector3d> Points(const MapCloudIndex& cloud) {
  std::vector<Eigen::Vector3d> points;
  points.reserve(cloud.size());
  for (int i = 0; i < static_cast<int>(cloud.size()); ++i) points.push_back(cloud.point(i));
  return points;
}

}  // namespace

CloudSurfaces::CloudSurfaces(const MapCloudIndex& cloud, const CloudSurfaceOptions& options)
    // Buckets of about twice the radius: a query visits at most eight of a few dozen points each.
    : index_(Points(cloud), 2.0 * options.radius), options_(options) {
  options_.Check();
}

std::optional<CloudSurface> CloudSurfaces::Fit(const Eigen::Vector3d& near) const {
  const std::vector<int> neighbours = index_.Near(near, options_.radius);
  if (static_cast<int>(neighbours.size()) < options_.min_points) return std::nullopt;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const int i : neighbours) mean += index_.point(i);
  mean /= static_cast<double>(neighbours.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const int i : neighbours) {
    const Eigen::Vector3d centred = index_.point(i) - mean;
    scatter += centred * centred.transpose();
  }
  scatter /= static_cast<double>(neighbours.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);  // ascending
  const double thickness = std::sqrt(std::max(0.0, eigen.eigenvalues()(0)));
  const double spread = std::sqrt(std::max(0.0, eigen.eigenvalues()(1)));
  if (thickness > options_.max_thickness || spread < options_.min_spread * options_.radius) {
    return std::nullopt;
  }
  CloudSurface surface;
  surface.plane_in_map = Plane::FromPointAndNormal(mean, eigen.eigenvectors().col(0));
  surface.thickness = thickness;
  surface.num_points = static_cast<int>(neighbours.size());
  return surface;
}

int CloudSurfaces::Associate(WindowProblem& problem, const WindowPointEstimates& estimates,
                             const PlaneAssociationOptions& gate) const {
  int next_id = 0;
  for (const WindowPlane& plane : problem.planes) next_id = std::max(next_id, plane.id + 1);
  std::vector<WindowPlane> patches;
  std::vector<std::pair<int, double>> associated;  // window point index, sigma
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    if (!estimates[i] || problem.points[i].plane_id) continue;
    const std::optional<CloudSurface> surface = Fit(estimates[i]->point_in_map);
    if (!surface) continue;
    const Eigen::Vector3d& n = surface->plane_in_map.normal;
    const double s = surface->plane_in_map.SignedDistance(estimates[i]->point_in_map);
    const double variance = n.dot(estimates[i]->covariance * n) +
                            surface->thickness * surface->thickness +
                            gate.map_sigma * gate.map_sigma;
    if (std::abs(s) > gate.max_distance || s * s > gate.gate_chi2 * variance) continue;
    WindowPlane patch;
    patch.id = next_id + static_cast<int>(patches.size());
    patch.plane_in_world = surface->plane_in_map;
    patches.push_back(patch);
    associated.emplace_back(static_cast<int>(i), std::sqrt(variance));
  }
  const int associations = static_cast<int>(associated.size());
  if (associations < gate.min_associations) return associations;  // staged activation
  for (std::size_t k = 0; k < associated.size(); ++k) {
    WindowPoint& point = problem.points[associated[k].first];
    point.plane_id = patches[k].id;
    point.plane_sigma = associated[k].second;
  }
  problem.planes.insert(problem.planes.end(), patches.begin(), patches.end());
  return associations;
}

}  // namespace planeloc
