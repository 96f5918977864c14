#include "planeloc/prior/map_lock.h"

#include <fmt/format.h>

#include <cmath>
#include <exception>
#include <limits>
#include <numbers>
#include <set>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;

std::string JsonNumber(double value, int digits) {
  return std::isfinite(value) ? fmt::format("{:.{}f}", value, digits) : std::string("null");
}

}  // namespace

std::string RegistrationReport::ToJson() const {
  std::string dofs;
  for (int dof = 0; dof < kNumDofs; ++dof) {
    if (!result.constrained[dof]) continue;
    if (!dofs.empty()) dofs += ",";
    dofs += fmt::format("\"{}\"", RegistrationDofName(dof));
  }
  std::string sigmas;
  for (int dof = 0; dof < kNumDofs; ++dof) {
    // Metres for the shifts, degrees for the angles.
    const double value = dof < 3 ? result.dof_sigma[dof] : result.dof_sigma[dof] / kDegree;
    sigmas +=
        fmt::format("{}\"{}\":{}", dof ? "," : "", RegistrationDofName(dof), JsonNumber(value, 5));
  }
  std::string eigenvalues;
  for (int i = 0; i < 6; ++i) {
    eigenvalues +=
        fmt::format("{}{}", i ? "," : "", JsonNumber(result.information_eigenvalues(i), 3));
  }
  const Eigen::Vector3d t = result.map_from_world.translation;
  const Eigen::Vector3d ct = result.candidate_map_from_world.translation;
  const Eigen::Quaterniond& cq = result.candidate_map_from_world.rotation;
  return fmt::format(
      "{{\"keyframe\":{},\"maintenance\":{},\"applied\":{},\"lock\":\"{}\",\"points\":{},"
      "\"inliers\":{},\"inlier_ratio\":{},"
      "\"rms\":{},\"whitened_rms\":{},\"margin\":{},\"hypotheses\":{},\"constrained\":[{}],\"dof_"
      "sigma\":{{{}}},"
      "\"information_eigenvalues\":[{}],\"correction\":{{\"translation\":[{:.4f},{:.4f},{:.4f}],"
      "\"angle_deg\":{:.4f}}},\"candidate\":{{\"translation\":[{:.4f},{:.4f},{:.4f}],"
      "\"rotation_xyzw\":[{:.6f},{:.6f},{:.6f},{:.6f}]}},\"fusion\":{},\"reason\":\"{}\"}}",
      keyframe_id, maintenance, applied, MapLockName(lock_after), result.points, result.inliers,
      JsonNumber(result.inlier_ratio, 4), JsonNumber(result.rms, 4),
      JsonNumber(result.whitened_rms, 3), JsonNumber(result.margin, 3), result.hypotheses, dofs,
      sigmas, eigenvalues, t.x(), t.y(), t.z(),
      RotationAngle(result.map_from_world.rotation, Eigen::Quaterniond::Identity()) / kDegree,
      ct.x(), ct.y(), ct.z(), cq.x(), cq.y(), cq.z(), cq.w(),
      fusion ? fusion->ToJson() : std::string("null"), result.reason);
}

std::string FusedCorrection::ToJson() const {
  std::string registered_json, applied_json, sigma_json, changed_json;
  for (int dof = 0; dof < kNumDofs; ++dof) {
    // Metres for the shifts, degrees for the angles.
    const double unit = dof < 3 ? 1.0 : 1.0 / kDegree;
    const char* separator = dof ? "," : "";
    registered_json += fmt::format("{}\"{}\":{}", separator, RegistrationDofName(dof),
                                   JsonNumber(registered(dof) * unit, 5));
    applied_json += fmt::format("{}\"{}\":{}", separator, RegistrationDofName(dof),
                                JsonNumber(applied(dof) * unit, 5));
    if (changed_dofs[dof]) {
      changed_json +=
          fmt::format("{}\"{}\"", changed_json.empty() ? "" : ",", RegistrationDofName(dof));
    }
    sigma_json += fmt::format("{}\"{}\":{}", separator, RegistrationDofName(dof),
                              JsonNumber(innovation_sigma(dof) * unit, 5));
  }
  return fmt::format(
      "{{\"accepted\":{},\"changed\":[{}],\"registered\":{{{}}},\"applied\":{{{}}},\"innovation_"
      "sigma\":{{{}}},\"worst_sigmas\":{},"
      "\"worst_dof\":\"{}\"}}",
      accepted, changed_json, registered_json, applied_json, sigma_json,
      JsonNumber(worst_sigmas, 3), worst_dof >= 0 ? RegistrationDofName(worst_dof) : "none");
}

MapLocker::MapLocker(const PlaneMap& planes, const MapLockOptions& options, const StartPrior& start,
                     const Rigid3d& world_from_cam_initial)
    : options_(options), registration_(planes, options.registration) {
  options_.Check();
  start.Check();
  const Eigen::Vector3d camera_up = world_from_cam_initial.rotation * Eigen::Vector3d(0, -1, 0);
  up_in_world_ = registration_.UpDirection(camera_up);
  pivot_in_world_ = world_from_cam_initial.translation;
  forward_in_world_ = world_from_cam_initial.rotation * Eigen::Vector3d::UnitZ();
  sigma_along_ = sigma_lateral_ = start.sigma_horizontal;
  sigma_vertical_ = start.sigma_vertical;
  sigma_yaw_ = start.sigma_yaw_deg * kDegree;
  if (start.Exact()) state_ = MapLock::kLocked;
}

RegistrationPrior MapLocker::CurrentPrior(const Eigen::Vector3d& camera_in_world) const {
  // Visual odometry drifts while the car drives away from the pivot: the prior widens with it.
  const double driven = (camera_in_world - pivot_in_world_).norm();
  const double drift = options_.drift_fraction * driven;
  const double yaw_drift = options_.drift_yaw_deg_per_100m * kDegree * driven / 100.0;
  return RegistrationPrior::FromVehicleSigmas(
      pivot_in_world_, up_in_world_, forward_in_world_, std::hypot(sigma_along_, drift),
      std::hypot(sigma_lateral_, drift), std::hypot(sigma_vertical_, 0.2 * drift),
      std::hypot(sigma_yaw_, yaw_drift), options_.registration.sigma_tilt_deg * kDegree);
}

bool MapLocker::AttemptDue(int keyframe_id) {
  if (keyframe_id < segment_first_keyframe_) return false;
  const bool maintenance = state_ == MapLock::kLocked;
  if (maintenance && options_.maintain_every_keyframes == 0) return false;
  const int every =
      maintenance ? options_.maintain_every_keyframes : options_.attempt_every_keyframes;
  return ++keyframes_since_attempt_ >= every;
}

RegistrationJob MapLocker::MakeJob(const SparseMap& map, int keyframe_id,
                                   const StereoCamera& camera) {
  keyframes_since_attempt_ = 0;
  const bool maintenance = state_ == MapLock::kLocked;
  // Structure: the points of the segment's last keyframes, copied for the worker.
  RegistrationJob job;
  job.segment = segment_;
  job.keyframe_id = keyframe_id;
  job.first_keyframe_id = keyframe_id;
  job.maintenance = maintenance;
  std::set<int> point_ids;
  int taken = 0;
  for (auto it = map.keyframes().rbegin();
       it != map.keyframes().rend() && taken < options_.structure_keyframes; ++it, ++taken) {
    if (it->first < segment_first_keyframe_) break;
    job.first_keyframe_id = it->first;
    for (const int id : it->second.map_point_ids) {
      if (id >= 0) point_ids.insert(id);
    }
  }
  const double depth_scale = options_.disparity_sigma_px / (camera.fx * camera.baseline);
  for (const int id : point_ids) {
    if (!map.HasPoint(id)) continue;
    const MapPoint& point = map.point(id);
    if (static_cast<int>(point.observations.size()) < options_.min_point_observations) continue;
    // A re-registration registers only what its correction moves (points created by the
    // structure's keyframes).
    if (point.first_keyframe_id < (maintenance ? job.first_keyframe_id : segment_first_keyframe_))
      continue;
    if (!map.HasKeyframe(point.reference_keyframe_id)) continue;
    const double distance =
        (point.point_in_world - map.keyframe(point.reference_keyframe_id).CameraCenter()).norm();
    if (distance > options_.max_point_distance) continue;
    job.points.push_back({point.point_in_world, distance * distance * depth_scale});
  }
  job.world_from_camera = map.keyframe(keyframe_id).cam_from_world.Inverse();
  if (maintenance) {
    // Around the current estimate, pivoted at the camera; roll and pitch as at the start.
    job.prior = RegistrationPrior::FromSigmas(
        job.world_from_camera.translation, up_in_world_, options_.maintain_sigma_horizontal,
        options_.maintain_sigma_vertical, options_.maintain_sigma_yaw_deg * kDegree,
        options_.registration.sigma_tilt_deg * kDegree);
  } else {
    job.prior = CurrentPrior(job.world_from_camera.translation);
  }

  return job;
}

void MapLocker::Run(RegistrationJob& job) const {
  try {
    job.result = registration_.Register(job.points, job.prior, job.world_from_camera);
  } catch (const std::exception& e) {
    RegistrationResult failed;
    failed.reason = std::string("registration failed: ") + e.what();
    job.result = failed;
  }
}

std::string ReasonCategory(const std::string& reason) {
  const std::string refused = "refused: ";
  if (reason.rfind(refused, 0) == 0) {
    const std::size_t in = reason.find(" in ");
    const std::size_t end = reason.find(" (", in == std::string::npos ? 0 : in);
    return in == std::string::npos ? "refused"
                                   : "refused: beyond the gate" + reason.substr(in, end - in);
  }
  return reason.substr(0, reason.find(" ("));
}

std::optional<std::pair<RegistrationReport, std::optional<MapCorrection>>> MapLocker::Finish(
    RegistrationJob job) {
  auto finished = FinishAttempt(std::move(job));
  if (finished && !finished->first.maintenance && finished->first.lock_before != MapLock::kLocked) {
    ++attempts_before_lock_;
    const std::string& reason = finished->first.result.reason;
    if (!finished->first.applied) ++refusals_[reason.empty() ? "unknown" : ReasonCategory(reason)];
  }
  return finished;
}

std::optional<std::pair<RegistrationReport, std::optional<MapCorrection>>> MapLocker::FinishAttempt(
    RegistrationJob job) {
  if (!job.result) return std::nullopt;
  RegistrationReport report;
  report.keyframe_id = job.keyframe_id;
  report.lock_before = state_;
  report.result = *job.result;
  report.lock_after = state_;
  if (job.segment != segment_) return std::nullopt;  // a loss since: its frame is gone
  report.maintenance = job.maintenance;
  std::optional<MapCorrection> correction;
  const MapLock found = report.result.lock;
  if (found == MapLock::kSearching) return std::make_pair(report, correction);
  // A partial result never downgrades a partial lock; a full one completes any. While locked,
  // only a re-registration can correct.
  const bool worth_applying =
      job.maintenance ? state_ == MapLock::kLocked
                      : (found == MapLock::kLocked && state_ != MapLock::kLocked) ||
                            (found == MapLock::kPartial && state_ == MapLock::kSearching);
  if (!worth_applying) return std::make_pair(report, correction);

  // The registration is evidence about the camera's pose; the job's prior is what the run knows
  // of it (the start prior grown with the distance driven, or what a partial lock left).
  const Matrix6d current =
      PriorCovarianceAtCamera(job.prior, report.result.camera_in_world, report.result.vehicle_axes);
  report.fusion = FuseRegistration(report.result, current, options_.max_correction_sigmas,
                                   options_.min_correction_sigmas);
  const FusedCorrection& fusion = *report.fusion;
  if (!fusion.accepted) {
    report.result.reason = fmt::format(
        "refused: {:.1f} sigma from the current estimate in {} (limit {:.1f})", fusion.worst_sigmas,
        RegistrationDofName(fusion.worst_dof), options_.max_correction_sigmas);
    return std::make_pair(report, correction);
  }
  if (job.maintenance) {
    if (!SignificantRecorrection(report.result, fusion)) {
      report.result.reason = "consistent with the map (below the re-correction threshold)";
      return std::make_pair(report, correction);
    }
    correction = MapCorrection{fusion.map_from_world, job.first_keyframe_id,
                               fusion.camera_position_covariance, /*recorrection=*/true};
    report.applied = true;
    return std::make_pair(report, correction);
  }
  correction = MapCorrection{fusion.map_from_world, segment_first_keyframe_,
                             fusion.camera_position_covariance};
  state_ = found;
  report.lock_after = found;
  report.applied = true;
  keyframes_since_attempt_ = 0;
  if (found == MapLock::kPartial) {
    // Next attempt: the registered DoF are known; along-track keeps its prior, now pivoted at
    // the camera (in the corrected frame).
    const Rigid3d& correction_transform = fusion.map_from_world;
    const Eigen::Vector3d camera = correction_transform * job.world_from_camera.translation;
    const double driven = (job.world_from_camera.translation - pivot_in_world_).norm();
    sigma_along_ = std::hypot(sigma_along_, options_.drift_fraction * driven);
    sigma_lateral_ = options_.partial_sigma_lateral;
    sigma_vertical_ = options_.partial_sigma_vertical;
    sigma_yaw_ = options_.partial_sigma_yaw_deg * kDegree;
    pivot_in_world_ = camera;
    forward_in_world_ =
        correction_transform.rotation * (job.world_from_camera.rotation * Eigen::Vector3d::UnitZ());
    up_in_world_ = correction_transform.rotation * up_in_world_;
  }
  return std::make_pair(report, correction);
}

bool MapLocker::SignificantRecorrection(const RegistrationResult& result,
                                        const FusedCorrection& fusion) const {
  for (int dof = kAlongTrack; dof <= kVertical; ++dof) {
    if (!fusion.registered_dofs[dof]) continue;
    const double threshold =
        std::max(options_.min_recorrection, options_.recorrection_sigmas * result.dof_sigma[dof]);
    if (std::abs(fusion.applied(dof)) > threshold) return true;
  }
  return fusion.applied.tail<3>().norm() > options_.min_recorrection_deg * kDegree;
}

void MapLocker::OnLoss(const Rigid3d& world_from_cam, int next_keyframe_id) {
  ++segment_;
  segment_first_keyframe_ = next_keyframe_id;
  keyframes_since_attempt_ = 0;
  const double driven = (world_from_cam.translation - pivot_in_world_).norm();
  const double drift = state_ == MapLock::kSearching ? options_.drift_fraction * driven : 0.0;
  if (state_ != MapLock::kSearching) {
    // The map frame was known up to the loss: the prior is what the motion model lost since.
    sigma_along_ = sigma_lateral_ = options_.lost_sigma_horizontal;
    sigma_vertical_ = options_.lost_sigma_vertical;
    sigma_yaw_ = options_.lost_sigma_yaw_deg * kDegree;
  } else {
    sigma_along_ = std::hypot(std::hypot(sigma_along_, drift), options_.lost_sigma_horizontal);
    sigma_lateral_ = std::hypot(std::hypot(sigma_lateral_, drift), options_.lost_sigma_horizontal);
    sigma_vertical_ = std::hypot(sigma_vertical_, options_.lost_sigma_vertical);
    sigma_yaw_ = std::hypot(sigma_yaw_, options_.lost_sigma_yaw_deg * kDegree);
  }
  pivot_in_world_ = world_from_cam.translation;
  forward_in_world_ = world_from_cam.rotation * Eigen::Vector3d::UnitZ();
  state_ = MapLock::kSearching;
}

}  // namespace planeloc
