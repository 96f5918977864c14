// The registration's names, options check and priors (declared in map_registration.h).
#include <cmath>
#include <string>

#include "planeloc/prior/map_registration.h"
#include "planeloc/prior/vehicle_axes.h"
#include "planeloc/util/error.h"

namespace planeloc {

const char* RegistrationDofName(int dof) {
  static const char* const kNames[kNumDofs] = {"along_track", "lateral", "vertical",
                                               "roll",        "pitch",   "yaw"};
  return dof >= 0 && dof < kNumDofs ? kNames[dof] : "unknown";
}

const char* MapLockName(MapLock lock) {
  switch (lock) {
    case MapLock::kSearching:
      return "searching";
    case MapLock::kPartial:
      return "partial";
    case MapLock::kLocked:
      return "locked";
  }
  return "unknown";
}

void MapRegistrationOptions::Check() const {
  auto positive = [](double value, const char* name) {
    if (!(value > 0.0))
      throw OptionsError(std::string("MapRegistrationOptions.") + name + " must be > 0");
  };
  positive(search_sigmas, "search_sigmas");
  positive(heading_step_deg, "heading_step_deg");
  positive(shift_cell, "shift_cell");
  positive(outline_margin, "outline_margin");
  positive(inlier_sigmas, "inlier_sigmas");
  positive(min_point_sigma, "min_point_sigma");
  positive(max_whitened_rms, "max_whitened_rms");
  positive(min_margin, "min_margin");
  positive(distinct_shift, "distinct_shift");
  positive(distinct_angle_deg, "distinct_angle_deg");
  positive(max_dof_sigma, "max_dof_sigma");
  positive(max_dof_sigma_deg, "max_dof_sigma_deg");
  positive(max_tilt_sigma_deg, "max_tilt_sigma_deg");
  positive(noise_inflation, "noise_inflation");
  positive(sigma_tilt_deg, "sigma_tilt_deg");
  positive(vertical_bin, "vertical_bin");
  positive(huber_sigmas, "huber_sigmas");
  positive(prior_variance_floor, "prior_variance_floor");
  positive(regularizer_sigma, "regularizer_sigma");
  positive(unobserved_shift_sigma, "unobserved_shift_sigma");
  positive(unobserved_angle_sigma, "unobserved_angle_sigma");
  auto non_negative = [](double value, const char* name) {
    if (!(value >= 0.0))
      throw OptionsError(std::string("MapRegistrationOptions.") + name + " must be >= 0");
  };
  non_negative(search_margin, "search_margin");
  non_negative(reach_margin, "reach_margin");
  non_negative(vertical_search_margin, "vertical_search_margin");
  non_negative(ground_band, "ground_band");
  non_negative(duplicate_peak_shift, "duplicate_peak_shift");
  non_negative(duplicate_peak_angle_deg, "duplicate_peak_angle_deg");
  auto tilt = [](double value, const char* name) {
    if (!(value > 0.0 && value < 90.0))
      throw OptionsError(std::string("MapRegistrationOptions.") + name + " must be in (0, 90) deg");
  };
  tilt(ground_max_tilt_deg, "ground_max_tilt_deg");
  tilt(facade_max_tilt_deg, "facade_max_tilt_deg");
  if (association_gates.empty()) {
    throw OptionsError("MapRegistrationOptions.association_gates must not be empty");
  }
  for (const double gate : association_gates) {
    if (!(gate >= 0.0 && std::isfinite(gate))) {
      throw OptionsError("MapRegistrationOptions.association_gates must be finite and >= 0 (m)");
    }
  }
  if (peaks_per_heading < 1) {
    throw OptionsError("MapRegistrationOptions.peaks_per_heading must be >= 1");
  }
  if (max_headings < 1) throw OptionsError("MapRegistrationOptions.max_headings must be >= 1");
  if (max_cells < 3) throw OptionsError("MapRegistrationOptions.max_cells must be >= 3");
  if (max_points < 10) throw OptionsError("MapRegistrationOptions.max_points must be >= 10");
  if (min_points < 10) throw OptionsError("MapRegistrationOptions.min_points must be >= 10");
  if (num_hypotheses < 1) throw OptionsError("MapRegistrationOptions.num_hypotheses must be >= 1");
  if (!(min_plane_area >= 0.0)) {
    throw OptionsError("MapRegistrationOptions.min_plane_area must be >= 0 (m^2)");
  }
  if (!(map_sigma >= 0.0)) throw OptionsError("MapRegistrationOptions.map_sigma must be >= 0 (m)");
  if (!(min_inlier_ratio >= 0.0 && min_inlier_ratio <= 1.0)) {
    throw OptionsError("MapRegistrationOptions.min_inlier_ratio must be in [0, 1]");
  }
}

RegistrationPrior RegistrationPrior::FromSigmas(const Eigen::Vector3d& pivot,
                                                const Eigen::Vector3d& up, double sigma_horizontal,
                                                double sigma_vertical, double sigma_yaw,
                                                double sigma_tilt) {
  return FromVehicleSigmas(pivot, up, AnyPerpendicular(up.normalized()), sigma_horizontal,
                           sigma_horizontal, sigma_vertical, sigma_yaw, sigma_tilt);
}

RegistrationPrior RegistrationPrior::FromVehicleSigmas(const Eigen::Vector3d& pivot,
                                                       const Eigen::Vector3d& up,
                                                       const Eigen::Vector3d& forward,
                                                       double sigma_along, double sigma_lateral,
                                                       double sigma_vertical, double sigma_yaw,
                                                       double sigma_tilt) {
  const VehicleAxes axes = AxesAt(forward, up);
  RegistrationPrior prior;
  prior.pivot_in_world = pivot;
  prior.up_in_world = axes.up;
  prior.covariance.setZero();
  prior.covariance.topLeftCorner<3, 3>() =
      sigma_along * sigma_along * axes.along * axes.along.transpose() +
      sigma_lateral * sigma_lateral * axes.lateral * axes.lateral.transpose() +
      sigma_vertical * sigma_vertical * axes.up * axes.up.transpose();
  prior.covariance.bottomRightCorner<3, 3>() =
      sigma_yaw * sigma_yaw * axes.up * axes.up.transpose() +
      sigma_tilt * sigma_tilt *
          (axes.along * axes.along.transpose() + axes.lateral * axes.lateral.transpose());
  return prior;
}

}  // namespace planeloc
