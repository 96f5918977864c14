// The raw LiDAR map's half of the local BA window in depth mode: the visual map points that lie on
// a locally flat patch of the map cloud get a point-to-plane residual against that patch, so the
// window BA pulls the keyframes and points onto the map as plane mode does with planes.json, on
// any flat surface (road, embankment, barrier, wall) and without a plane map. The patch is the
// total-least-squares plane of the cloud points within `radius` of the point's visual estimate;
// vegetation, poles and edges are too thick or too thin to be a patch and give no residual.
#pragma once

#include <optional>
#include <vector>

#include "planeloc/geometry/plane.h"
#include "planeloc/optim/window_ba.h"
#include "planeloc/prior/depth_prior_options.h"
#include "planeloc/prior/map_cloud_index.h"
#include "planeloc/prior/plane_association.h"
#include "planeloc/prior/window_planes.h"

namespace planeloc {

struct CloudSurface {
  Plane plane_in_map;
  double thickness = 0;  // m, RMS along the normal
  int num_points = 0;
};

// The map cloud's points, indexed for the patch queries (fine buckets, unlike the depth
// residual's MapCloudIndex which serves a 40 m ball per frame).
class CloudSurfaces {
 public:
  CloudSurfaces(const MapCloudIndex& cloud, const CloudSurfaceOptions& options);

  // The patch around `near`, or std::nullopt where the cloud has no flat patch there.
  std::optional<CloudSurface> Fit(const Eigen::Vector3d& near) const;

  // Gives every window point whose visual estimate passes the plane gate of its patch
  // (gate.gate_chi2 on sigma^2 = n^T Sigma n + thickness^2 + gate.map_sigma^2, |s| <=
  // gate.max_distance) a point-to-plane residual against it: one WindowPlane per point, ids after
  // the problem's existing planes. Fewer than gate.min_associations points: none (staged
  // activation, as AssociateWindowPlanes). Returns the points that passed the gate.
  int Associate(WindowProblem& problem, const WindowPointEstimates& estimates,
                const PlaneAssociationOptions& gate) const;

 private:
  MapCloudIndex index_;
  CloudSurfaceOptions options_;
};

}  // namespace planeloc
