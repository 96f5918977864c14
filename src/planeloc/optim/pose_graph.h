// A pose graph over sensor poses world_from_node: absolute priors (GNSS/INS poses, or any poses
// with known noise) and relative measurements between nodes (scan registration), solved in
// Ceres. Used to refine the poses a LiDAR map is accumulated with (map/pose_refinement.h):
// independent pose noise of a few centimetres blurs every surface into layers; registration
// ties neighbouring scans to millimetres, and the priors keep the whole in the poses' frame.
//
// Error of a pose T against a measurement M (both world_from_node, or both i_from_j):
//   E = M^-1 * T,  r = [2 vec(q_E) / sigma_rotation, t_E / sigma_translation]  (6 rows)
// (2 vec(q) is the rotation vector to first order). Relative terms get a Huber kernel (a
// registration can fail); priors do not.
#pragma once

#include <vector>

#include "planeloc/geometry/rigid3.h"

namespace planeloc {

struct PoseGraphOptions {
  double huber = 3.0;   // whitened units, relative terms
  int iterations = 50;  // Levenberg-Marquardt
  int num_threads = 1;
  void Check() const;  // throws OptionsError naming the field
};

struct PosePrior {
  Rigid3d world_from_node;
  double sigma_translation = 0.05;  // metres, per axis
  double sigma_rotation = 0.0035;   // radians, per axis
};

struct RelativePose {
  int from = 0, to = 0;  // node indices
  Rigid3d from_from_to;  // the pose of `to` in `from`'s frame
  double sigma_translation = 0.01;
  double sigma_rotation = 0.0005;
};

struct PoseGraphResult {
  std::vector<Rigid3d> world_from_node;  // one per prior
  bool usable = false;
  double initial_cost = 0, final_cost = 0;
  int iterations = 0;
};

// One node per prior, initialised at it. Throws std::invalid_argument for an edge with an unknown
// node or a non-positive sigma.
PoseGraphResult SolvePoseGraph(const std::vector<PosePrior>& priors,
                               const std::vector<RelativePose>& edges,
                               const PoseGraphOptions& options);

}  // namespace planeloc
