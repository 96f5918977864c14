#include "planeloc/prior/map_lock_options.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <numbers>

#include "planeloc/util/error.h"

namespace planeloc {

void StartPrior::Check() const {
  const double values[3] = {sigma_horizontal, sigma_vertical, sigma_yaw_deg};
  const double maxima[3] = {kMaxSigmaHorizontal, kMaxSigmaVertical, kMaxSigmaYawDeg};
  for (int i = 0; i < 3; ++i) {
    if (!(std::isfinite(values[i]) && values[i] >= 0.0 && values[i] <= maxima[i])) {
      throw OptionsError(fmt::format(
          "--init-sigma \"S_XY S_Z S_YAW_DEG\" needs 0 <= S_XY <= {} m, 0 <= S_Z <= {} m and 0 <= "
          "S_YAW_DEG <= {} deg (the map registration's search range), got \"{} {} {}\"",
          kMaxSigmaHorizontal, kMaxSigmaVertical, kMaxSigmaYawDeg, sigma_horizontal, sigma_vertical,
          sigma_yaw_deg));
    }
  }
}

std::string StartPriorWarning(const PlaneMap& planes, const Eigen::Vector3d& start_position,
                              const StartPrior& prior) {
  if (prior.Exact() || planes.planes.empty()) return "";
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  double nearest = std::numeric_limits<double>::infinity();
  for (const MapPlane& plane : planes.planes) {
    if (plane.polygon.empty()) continue;
    Eigen::Vector3d plane_lo = plane.polygon.front(), plane_hi = plane_lo;
    for (const Eigen::Vector3d& p : plane.polygon) {
      plane_lo = plane_lo.cwiseMin(p);
      plane_hi = plane_hi.cwiseMax(p);
    }
    lo = lo.cwiseMin(plane_lo);
    hi = hi.cwiseMax(plane_hi);
    const Eigen::Vector3d outside =
        (plane_lo - start_position).cwiseMax(start_position - plane_hi).cwiseMax(0.0);
    nearest = std::min(nearest, outside.norm());
  }
  if (!std::isfinite(nearest)) return "";  // no outlines: nothing to compare with
  const std::string map_name = planes.source.empty() ? "the plane map" : planes.source.string();
  // The structure reaches 20 m from the camera (MapLockOptions::max_point_distance).
  const double reach = 3.0 * std::hypot(prior.sigma_horizontal, prior.sigma_vertical) + 20.0;
  if (nearest > reach) {
    return fmt::format(
        "{}: the initial pose is {:.0f} m from the nearest plane, beyond what --init-sigma \"{} {} "
        "{}\" can reach ({:.0f} m); the run stays visual odometry (map lock: searching) unless it "
        "drives into the map. Check that the initial pose is in the plane map's frame.",
        map_name, nearest, prior.sigma_horizontal, prior.sigma_vertical, prior.sigma_yaw_deg,
        reach);
  }
  const double extent = (hi - lo).maxCoeff();
  if (3.0 * prior.sigma_horizontal > extent) {
    return fmt::format(
        "{}: --init-sigma \"{} {} {}\" is wider than the map ({:.0f} m across): the registration "
        "may find several places that fit; the run stays visual odometry (map lock: searching) "
        "until one fits clearly better. Narrow the prior if the start is known better.",
        map_name, prior.sigma_horizontal, prior.sigma_vertical, prior.sigma_yaw_deg, extent);
  }
  return "";
}

void MapLockOptions::Check() const {
  registration.Check();
  if (attempt_every_keyframes < 1) {
    throw OptionsError("MapLock.attemptEveryKeyframes must be >= 1");
  }
  if (structure_keyframes < 1) throw OptionsError("MapLock.structureKeyframes must be >= 1");
  if (settle_keyframes < 0) throw OptionsError("MapLock.settleKeyframes must be >= 0");
  if (maintain_every_keyframes < 0) {
    throw OptionsError("MapLock.maintainEveryKeyframes must be >= 0 (0: never)");
  }
  if (!(max_correction_sigmas > 0)) {
    throw OptionsError("MapLock.maxCorrectionSigmas must be > 0");
  }
  if (!(min_correction_sigmas >= 0 && min_correction_sigmas < max_correction_sigmas)) {
    throw OptionsError("MapLock.minCorrectionSigmas must be >= 0 and < maxCorrectionSigmas");
  }
  for (const double value :
       {maintain_sigma_horizontal, maintain_sigma_vertical, maintain_sigma_yaw_deg,
        min_recorrection, recorrection_sigmas, min_recorrection_deg}) {
    if (!(value >= 0)) throw OptionsError("MapLock maintenance sigmas and thresholds must be >= 0");
  }
  if (!(max_point_distance > 0)) throw OptionsError("MapLock.maxPointDistance must be > 0 (m)");
  if (!(disparity_sigma_px > 0)) throw OptionsError("MapLock.disparitySigma must be > 0 (px)");
  for (const double value :
       {drift_fraction, drift_yaw_deg_per_100m, partial_sigma_lateral, partial_sigma_vertical,
        partial_sigma_yaw_deg, lost_sigma_horizontal, lost_sigma_vertical, lost_sigma_yaw_deg}) {
    if (!(value >= 0)) throw OptionsError("MapLock sigmas and drift rates must be >= 0");
  }
}

}  // namespace planeloc
