// Absolute pose error, translation part, as evo_ape -r trans_part:
//   error_i = |trans(P_ref,i^-1 * P_est,i)| = |p_est,i - p_ref,i|  (after alignment).
// Order as evo's CLI: 3-D Umeyama alignment first, then the optional projection to a plane.
// `project_before_align` reproduces evo's library order (project both, then align) instead.
#pragma once

#include <vector>

#include "planeloc/eval/alignment.h"
#include "planeloc/eval/pose_path.h"
#include "planeloc/eval/statistics.h"

namespace planeloc {

struct ApeOptions {
  AlignmentType alignment = AlignmentType::kNone;
  ProjectionPlane plane = ProjectionPlane::kNone;
  // false: align in 3-D, then project (evo_ape --project_to_plane). true: project both
  // trajectories first, then align the projected positions (evo library, Trajectory.project).
  bool project_before_align = false;

  // Throws OptionsError naming the field.
  void Check() const;
};

struct ApeResult {
  Sim3Alignment alignment;     // ref_from_est applied to the estimate
  PoseMatrices reference;      // after the projection (if any)
  PoseMatrices estimate;       // after alignment and projection: what the errors compare
  std::vector<double> errors;  // metres, one per pose
  ErrorStatistics stats;
};

// Position distances of two equally long pose sequences, metres.
std::vector<double> PositionErrors(const PoseMatrices& reference, const PoseMatrices& estimate);

// `reference` and `estimate` are associated pose by pose (same length, >= 1).
// Throws InputError for empty or differently long inputs.
ApeResult ComputeApe(PoseMatrices reference, PoseMatrices estimate, const ApeOptions& options);

}  // namespace planeloc
