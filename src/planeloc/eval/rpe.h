// Relative pose error as evo_rpe (evo/core/metrics.py RPE, evo/core/filters.py):
//   E_ij = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j),  Q = reference, P = estimate,
// translation error |trans(E_ij)| (metres), rotation error angle(rot(E_ij)) (degrees).
//
// Pairs (i, j), chosen on the estimate's path after alignment and projection (evo's default) or on
// the reference's path (`pairs_from_reference`):
// - frames, consecutive: checkpoints 0, d, 2d, ...; pairs are consecutive checkpoints.
// - frames, all pairs:   (i, i + d) for every i.
// - metres, consecutive: walking the path, a checkpoint is set each time the path travelled since
//   the previous checkpoint reaches >= d (the first checkpoint is NOT index 0); pairs are
//   consecutive checkpoints.
// - metres, all pairs:   for every i, j = argmin_j |path(i..j) - d| found by evo's bounded binary
//   search, kept when |path(i..j) - d| <= relative_tolerance * d.
#pragma once

#include <utility>
#include <vector>

#include "planeloc/eval/alignment.h"
#include "planeloc/eval/pose_path.h"
#include "planeloc/eval/statistics.h"

namespace planeloc {

enum class DeltaUnit { kFrames, kMeters };
// "frames" | "f" | "m" | "meters" | "metres"; throws InputError otherwise.
DeltaUnit ParseDeltaUnit(const std::string& name);
std::string ToString(DeltaUnit unit);

struct RpeOptions {
  double delta = 1.0;  // frames (integer >= 1) or metres (> 0)
  DeltaUnit delta_unit = DeltaUnit::kFrames;
  bool all_pairs = false;             // every start index instead of consecutive checkpoints
  bool pairs_from_reference = false;  // choose pairs on the reference's path
  double relative_tolerance = 0.1;    // all-pairs metres: accepted |path - delta| / delta
  AlignmentType alignment = AlignmentType::kNone;
  ProjectionPlane plane = ProjectionPlane::kNone;  // applied after the 3-D alignment

  // Throws OptionsError naming the field.
  void Check() const;
};

using IndexPairs = std::vector<std::pair<std::size_t, std::size_t>>;

// The index pairs evo would compare on `poses` (no error when empty).
IndexPairs RpePairs(const PoseMatrices& poses, const RpeOptions& options);

struct RpeResult {
  Sim3Alignment alignment;
  IndexPairs pairs;
  std::vector<double> translation_errors;   // metres, one per pair
  std::vector<double> rotation_errors_deg;  // degrees, one per pair
  ErrorStatistics translation;
  ErrorStatistics rotation_deg;
};

// Throws InputError when the trajectories differ in length or no pair fits the delta.
RpeResult ComputeRpe(const PoseMatrices& reference, PoseMatrices estimate,
                     const RpeOptions& options);

}  // namespace planeloc
