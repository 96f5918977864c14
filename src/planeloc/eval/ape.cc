#include "planeloc/eval/ape.h"

#include <fmt/format.h>

#include "planeloc/util/error.h"

namespace planeloc {

void ApeOptions::Check() const {
  if (project_before_align && plane == ProjectionPlane::kNone) {
    throw OptionsError("ApeOptions.project_before_align needs a projection plane");
  }
}

std::vector<double> PositionErrors(const PoseMatrices& reference, const PoseMatrices& estimate) {
  std::vector<double> errors(reference.size());
  for (std::size_t i = 0; i < reference.size(); ++i) {
    errors[i] = (estimate[i].block<3, 1>(0, 3) - reference[i].block<3, 1>(0, 3)).norm();
  }
  return errors;
}

ApeResult ComputeApe(PoseMatrices reference, PoseMatrices estimate, const ApeOptions& options) {
  options.Check();
  if (reference.empty() || reference.size() != estimate.size()) {
    throw InputError("",
                     fmt::format("APE needs two equally long, non-empty trajectories ({} vs {})",
                                 reference.size(), estimate.size()),
                     "associate the trajectories first (same frames, or TUM timestamps)");
  }
  ApeResult result;
  if (options.project_before_align) {
    ProjectToPlane(options.plane, &reference);
    ProjectToPlane(options.plane, &estimate);
    result.alignment = AlignTrajectory(reference, options.alignment, &estimate);
  } else {
    result.alignment = AlignTrajectory(reference, options.alignment, &estimate);
    ProjectToPlane(options.plane, &reference);
    ProjectToPlane(options.plane, &estimate);
  }
  result.errors = PositionErrors(reference, estimate);
  result.stats = ComputeStatistics(result.errors);
  result.reference = std::move(reference);
  result.estimate = std::move(estimate);
  return result;
}

}  // namespace planeloc
