// The prior map's half of the local BA window: which of the window's points lie on a LiDAR plane,
// with what sigma, and the planes they use. The visual half is BuildLocalWindow
// (tracking/local_mapping.h).
#pragma once

#include <optional>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/optim/window_ba.h"
#include "planeloc/prior/plane_association.h"
#include "planeloc/tracking/map.h"

namespace planeloc {

// The point's position from its stereo observations only (each back-projected from its
// keyframe's current pose, fused by information; keypoint noise options.pixel_sigma times
// scale_factor^octave). std::nullopt when no observation has a stereo match.
std::optional<PointEstimate> VisualPointEstimate(const SparseMap& map, const MapPoint& point,
                                                 const StereoCamera& camera,
                                                 const PlaneAssociationOptions& options);

// The visual estimate (VisualPointEstimate) of each point of `problem`, in its order;
// std::nullopt for a point without a stereo observation.
using WindowPointEstimates = std::vector<std::optional<PointEstimate>>;
WindowPointEstimates EstimateWindowPoints(const WindowProblem& problem, const SparseMap& map,
                                          const StereoCamera& camera,
                                          const PlaneAssociationOptions& options);

// Records the window's estimates for the planes' bias statistics (PlaneAssociator::Record; the
// records stay pending until the caller closes and commits them).
void RecordWindow(const WindowProblem& problem, const WindowPointEstimates& estimates,
                  PlaneAssociator& planes);

// Associates the points of a window built by BuildLocalWindow with the plane map: every window
// point whose visual estimate passes the plane gate gets its plane id and the gate's sigma, and
// the planes used are added to the problem (fixed: WindowPlane without a correction prior). A
// window with fewer than options.min_associations associated points gets none (staged
// activation: plain visual BA). The decision uses the points' stereo measurements, not their BA
// positions (hysteresis). Changes nothing but `problem`; returns the number of points that
// passed the gate (before staged activation), for PlaneAssociator::UpdateHealth.
int AssociateWindowPlanes(WindowProblem& problem, const WindowPointEstimates& estimates,
                          const PlaneAssociationOptions& options, const PlaneAssociator& planes);

}  // namespace planeloc
