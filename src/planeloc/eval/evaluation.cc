#include "planeloc/eval/evaluation.h"

#include <fmt/format.h>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

void PairKittiByLine(EvalInputs* inputs, const EvalOptions& options) {
  if (inputs->reference.size() != inputs->estimate.size()) {
    throw InputError(
        inputs->est_path.string(),
        fmt::format("the estimate has {} poses but the GT {} has {}; KITTI files are "
                    "compared line by line",
                    inputs->estimate.size(), inputs->gt_path.string(), inputs->reference.size()),
        "write one pose per GT frame, or pass --gt-times and --est-times to pair "
        "by timestamp");
  }
  if (options.gt_times) {
    inputs->times = ReadTimestamps(*options.gt_times);
    if (inputs->times.size() != inputs->reference.size()) {
      throw InputError(options.gt_times->string(),
                       fmt::format("{} timestamps for the {} poses of {}", inputs->times.size(),
                                   inputs->reference.size(), inputs->gt_path.string()),
                       "pass the times.txt of the same sequence (one line per pose)");
    }
    inputs->has_time = true;
  } else {
    inputs->times.resize(inputs->reference.size());
    for (std::size_t i = 0; i < inputs->times.size(); ++i) inputs->times[i] = double(i);
  }
}

std::vector<double> ReadTimesFor(const std::filesystem::path& times_path,
                                 const std::filesystem::path& poses_path, std::size_t count) {
  std::vector<double> times = ReadTimestamps(times_path);
  if (times.size() != count) {
    throw InputError(times_path.string(),
                     fmt::format("{} timestamps for the {} poses of {}", times.size(), count,
                                 poses_path.string()),
                     "pass the times file that belongs to this pose file (one line per pose)");
  }
  return times;
}

void PairByTimestamp(const std::vector<double>& gt_times, const std::vector<double>& est_times,
                     double max_difference, EvalInputs* inputs) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  try {
    pairs = AssociateByTimestamp(gt_times, est_times, max_difference);
  } catch (const InputError& e) {
    throw InputError(inputs->est_path.string(),
                     fmt::format("{} (GT {})", e.problem(), inputs->gt_path.string()), e.fix());
  }
  PoseMatrices reference;
  PoseMatrices estimate;
  inputs->times.clear();
  for (const auto& [r, e] : pairs) {
    reference.push_back(inputs->reference[r]);
    estimate.push_back(inputs->estimate[e]);
    inputs->times.push_back(est_times[e]);
  }
  inputs->reference = std::move(reference);
  inputs->estimate = std::move(estimate);
  inputs->has_time = true;
}

}  // namespace

void EvalOptions::Check() const {
  if (!(max_time_difference_s >= 0.0)) {
    throw OptionsError(fmt::format("EvalOptions.max_time_difference_s must be >= 0, got {}",
                                   max_time_difference_s));
  }
  if (plane_before_align && plane == ProjectionPlane::kNone) {
    throw OptionsError("EvalOptions.plane_before_align needs a plane (--plane)");
  }
  if (format == TrajectoryFormat::kTum && (gt_times || est_times)) {
    throw OptionsError("EvalOptions.gt_times/est_times apply to KITTI files only (TUM has times)");
  }
  if (euroc_reference && format != TrajectoryFormat::kTum) {
    throw OptionsError("EvalOptions.euroc_reference needs format TUM (the estimate's format)");
  }
  if (est_times && !gt_times) {
    throw OptionsError("EvalOptions.est_times needs gt_times too (pairing by timestamp)");
  }
  if (rpe) rpe->Check();
  if (kitti_drift) drift.Check();
}

EvalInputs LoadEvalInputs(const std::filesystem::path& gt_path,
                          const std::filesystem::path& est_path, const EvalOptions& options) {
  options.Check();
  EvalInputs inputs;
  inputs.gt_path = gt_path;
  inputs.est_path = est_path;
  if (options.format == TrajectoryFormat::kKitti) {
    inputs.reference = ToPoseMatrices(ReadKittiPoseMatrices(gt_path));
    inputs.estimate = ToPoseMatrices(ReadKittiPoseMatrices(est_path));
    inputs.gt_size = inputs.reference.size();
    inputs.est_size = inputs.estimate.size();
    if (options.est_times) {
      const std::vector<double> gt_times =
          ReadTimesFor(*options.gt_times, gt_path, inputs.reference.size());
      const std::vector<double> est_times =
          ReadTimesFor(*options.est_times, est_path, inputs.estimate.size());
      PairByTimestamp(gt_times, est_times, options.max_time_difference_s, &inputs);
    } else {
      PairKittiByLine(&inputs, options);
    }
    return inputs;
  }
  const Trajectory gt =
      options.euroc_reference ? ReadEurocTrajectory(gt_path) : ReadTumTrajectory(gt_path);
  const Trajectory est = ReadTumTrajectory(est_path);
  inputs.reference = ToPoseMatrices(gt);
  inputs.estimate = ToPoseMatrices(est);
  inputs.gt_size = gt.size();
  inputs.est_size = est.size();
  PairByTimestamp(gt.timestamps, est.timestamps, options.max_time_difference_s, &inputs);
  return inputs;
}

EvalReport Evaluate(const EvalInputs& inputs, const EvalOptions& options) {
  options.Check();
  EvalReport report;
  ApeOptions ape;
  ape.alignment = options.alignment;
  ape.plane = options.plane;
  ape.project_before_align = options.plane_before_align;
  report.ape = ComputeApe(inputs.reference, inputs.estimate, ape);
  if (options.rpe) {
    RpeOptions rpe = *options.rpe;
    rpe.alignment = options.alignment;
    rpe.plane = options.plane;
    report.rpe = ComputeRpe(inputs.reference, inputs.estimate, rpe);
  }
  if (options.kitti_drift) {
    // Drift is measured in 3-D on the aligned estimate (SE(3) alignment leaves relative motion
    // unchanged; Sim(3) removes the scale error), never on the projection.
    PoseMatrices estimate = inputs.estimate;
    ApplyAlignment(report.ape.alignment, &estimate);
    if (options.plane_before_align) {
      // The APE alignment was fitted on projected positions; refit in 3-D for the drift.
      estimate = inputs.estimate;
      AlignTrajectory(inputs.reference, options.alignment, &estimate);
    }
    report.kitti_drift = ComputeKittiDrift(inputs.reference, estimate, options.drift);
  }
  return report;
}

}  // namespace planeloc
