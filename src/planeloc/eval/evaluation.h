// The whole `planeloc eval` computation as a library call: load GT and estimate, pair them
// (KITTI: line by line; TUM: by timestamp as evo), then APE, optional RPE and KITTI drift.
// The CLI (apps/cmd_eval.cc) only parses flags, prints and plots.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/eval/ape.h"
#include "planeloc/eval/kitti_drift.h"
#include "planeloc/eval/rpe.h"
#include "planeloc/io/trajectory.h"

namespace planeloc {

struct EvalOptions {
  TrajectoryFormat format = TrajectoryFormat::kKitti;
  // KITTI only: times.txt of the GT / estimate. With both, poses are paired by timestamp instead
  // of line by line; with the GT's only, they label the plot's time axis.
  std::optional<std::filesystem::path> gt_times;
  std::optional<std::filesystem::path> est_times;
  double max_time_difference_s = 0.01;  // TUM association tolerance, seconds (evo's default)
  // TUM only: the GT is a EuRoC csv (io/trajectory.h ReadEurocTrajectory; `eval --format euroc`,
  // as `evo_ape euroc GT.csv EST.tum`), the estimate a TUM file, paired by timestamp.
  bool euroc_reference = false;
  AlignmentType alignment = AlignmentType::kNone;
  ProjectionPlane plane = ProjectionPlane::kNone;  // applied after the 3-D alignment
  bool plane_before_align = false;                 // APE only: evo library order instead
  // RPE when set; its alignment and plane are overwritten by the ones above.
  std::optional<RpeOptions> rpe;
  bool kitti_drift = false;
  KittiDriftOptions drift;

  // Throws OptionsError naming the field.
  void Check() const;
};

// Associated poses: reference[k] and estimate[k] describe the same instant.
struct EvalInputs {
  std::filesystem::path gt_path;
  std::filesystem::path est_path;
  std::size_t gt_size = 0;   // poses in the GT file
  std::size_t est_size = 0;  // poses in the estimate file
  PoseMatrices reference;
  PoseMatrices estimate;
  // Time of each associated pose (seconds) when known, else the frame index; `has_time` tells.
  std::vector<double> times;
  bool has_time = false;
};

// Throws InputError for unreadable files, bad lines, KITTI files of different lengths,
// times.txt count mismatches and TUM files without overlapping timestamps.
EvalInputs LoadEvalInputs(const std::filesystem::path& gt_path,
                          const std::filesystem::path& est_path, const EvalOptions& options);

struct EvalReport {
  ApeResult ape;
  std::optional<RpeResult> rpe;
  std::optional<KittiDriftResult> kitti_drift;
};

EvalReport Evaluate(const EvalInputs& inputs, const EvalOptions& options);

}  // namespace planeloc
