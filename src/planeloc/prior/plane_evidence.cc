#include "planeloc/prior/plane_evidence.h"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// Rays are walked back from the point towards the camera in steps of this many metres, up to
// kThroughReach, to find planes whose lookup cells the point itself lies beyond.
constexpr double kThroughStep = 2.5;
constexpr double kThroughReach = 10.0;
// A fit of the tilt needs the points spread over the plane; below this many metres (rms of the
// in-plane coordinates along an axis) the tilt about the other axis is left unmeasured.
constexpr double kMinSpread = 1.0;
// Tilt sigma reported for an axis the points do not constrain (radians).
constexpr double kUnconstrainedTilt = 1.0;
constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;

double Median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

void PlaneEvidenceOptions::Check() const {
  const auto require = [](bool ok, const std::string& field) {
    if (!ok) throw OptionsError("MapUpdate." + field + " is out of range");
  };
  require(band > 0 && std::isfinite(band), "band");
  require(max_point_sigma > 0, "maxPointSigma");
  require(min_points >= 3, "minPoints");
  require(trajectory_sigma >= 0 && std::isfinite(trajectory_sigma), "trajectorySigma");
  require(trajectory_tilt_sigma_deg >= 0 && std::isfinite(trajectory_tilt_sigma_deg),
          "trajectoryTiltSigmaDeg");
  require(min_offset >= 0 && std::isfinite(min_offset), "minOffset");
  require(min_tilt_deg >= 0 && std::isfinite(min_tilt_deg), "minTiltDeg");
  require(chi2 > 0, "chi2");
}

PlaneEvidence::PlaneEvidence(const PlaneMap& map, const PlaneAssociator& associator,
                             const PlaneEvidenceOptions& options)
    : associator_(associator), options_(options) {
  options_.Check();
  for (const MapPlane& plane : map.planes) {
    PlaneRecord record;
    record.plane = plane;
    const Eigen::Vector3d& n = plane.plane_in_map.normal;
    record.e1 = plane.sigma.known() ? plane.sigma.major_axis : n.unitOrthogonal();
    record.e2 = n.cross(record.e1).normalized();
    if (record.plane.centroid.isZero()) {
      record.plane.centroid = -plane.plane_in_map.d * n;  // the plane's point nearest the origin
    }
    index_by_id_[plane.id] = records_.size();
    records_.push_back(std::move(record));
  }
}

void PlaneEvidence::ObserveWindow(int frame, const std::vector<EvidencePoint>& points) {
  std::set<std::size_t> seen;
  for (const EvidencePoint& point : points) {
    const Eigen::Vector3d& x = point.estimate.point_in_map;
    const Eigen::Vector3d& c = point.camera_center;
    if (!x.allFinite() || !c.allFinite() || !point.estimate.covariance.allFinite()) continue;
    candidates_.clear();
    const Eigen::Vector3d back = c - x;
    const double length = back.norm();
    const int steps = static_cast<int>(std::min(length, kThroughReach) / kThroughStep);
    for (int k = 0; k <= steps; ++k) {
      associator_.PlanesNear(k == 0 ? x : Eigen::Vector3d(x + back * (k * kThroughStep / length)),
                             candidates_);
    }
    std::sort(candidates_.begin(), candidates_.end());
    candidates_.erase(std::unique(candidates_.begin(), candidates_.end()), candidates_.end());
    for (const int id : candidates_) {
      const auto found = index_by_id_.find(id);
      if (found == index_by_id_.end()) continue;
      PlaneRecord& record = records_[found->second];
      const Plane& plane = record.plane.plane_in_map;
      const double s = plane.SignedDistance(x);
      const double s_camera = plane.SignedDistance(c);
      const double sigma =
          std::sqrt(std::max(0.0, plane.normal.dot(point.estimate.covariance * plane.normal)));
      // Behind the plane as seen from the camera, beyond its own depth uncertainty: the ray
      // crosses it at c + t (x - c).
      if (s * s_camera >= 0 || std::abs(s) <= options_.band + 3.0 * sigma) continue;
      const double t = s_camera / (s_camera - s);
      const Eigen::Vector3d crossing = c + t * (x - c);
      // Strictly inside the outline: at its edges a ray may pass beside the surface.
      if (!associator_.InsideOutline(id, crossing, 0.0)) continue;
      const Eigen::Vector3d at = crossing - record.plane.centroid;
      record.samples[point.point_id] = {at.dot(record.e1), at.dot(record.e2), s, true};
      seen.insert(found->second);
    }
    // On a plane: the bias statistics' rule (the plane's band clear of its parallel neighbours',
    // no crossing plane within it), disabled planes included (their offset is what a map update
    // reports), precise along the plane's normal, and inside the outline itself, not the
    // association's margin beyond it (there a kerb beside a road piece would be measured as the
    // plane's offset).
    const auto witness = associator_.WitnessedPlane(x, options_.band, /*disabled_too=*/true);
    if (!witness || !associator_.InsideOutline(witness->plane_id, x, 0.0)) continue;
    const auto found = index_by_id_.find(witness->plane_id);
    if (found == index_by_id_.end()) continue;
    PlaneRecord& record = records_[found->second];
    const Eigen::Vector3d& normal = record.plane.plane_in_map.normal;
    if (normal.dot(point.estimate.covariance * normal) >
        options_.max_point_sigma * options_.max_point_sigma) {
      continue;
    }
    const Eigen::Vector3d from_centroid = x - record.plane.centroid;
    record.samples[point.point_id] = {from_centroid.dot(record.e1), from_centroid.dot(record.e2),
                                      witness->distance, false};
    seen.insert(found->second);
  }
  for (const std::size_t index : seen) records_[index].frames.insert(frame);
}

void PlaneEvidence::NoteDisabled(int frame) {
  for (PlaneRecord& record : records_) {
    if (record.disabled_at_frame || !associator_.Contains(record.plane.id)) continue;
    if (associator_.health(record.plane.id).disabled) record.disabled_at_frame = frame;
  }
}

void PlaneEvidence::Reset() {
  for (PlaneRecord& record : records_) record.samples.clear();
}

std::vector<PlaneUpdate> PlaneEvidence::Summarize() const {
  std::vector<PlaneUpdate> updates;
  updates.reserve(records_.size());
  for (const PlaneRecord& record : records_) updates.push_back(Summarize(record));
  return updates;
}

PlaneUpdate PlaneEvidence::Summarize(const PlaneRecord& record) const {
  PlaneUpdate update;
  update.id = record.plane.id;
  update.frames.assign(record.frames.begin(), record.frames.end());
  update.disabled_at_frame = record.disabled_at_frame;
  std::vector<double> distances;
  std::vector<const Sample*> on_plane;
  for (const auto& [id, sample] : record.samples) {
    if (sample.through) {
      ++update.through;
    } else {
      distances.push_back(sample.s);
      on_plane.push_back(&sample);
    }
  }
  // Inliers of a median / MAD test (the MAD floored at 1 cm: stereo is not better).
  std::vector<const Sample*> inliers;
  if (!distances.empty()) {
    const double median = Median(distances);
    std::vector<double> deviations;
    for (const double s : distances) deviations.push_back(std::abs(s - median));
    const double spread = std::max(0.01, 1.4826 * Median(deviations));
    for (const Sample* sample : on_plane) {
      if (std::abs(sample->s - median) <= 3.0 * spread) inliers.push_back(sample);
    }
  }
  update.points = static_cast<int>(inliers.size());
  if (update.points < options_.min_points) {
    update.status = update.through >= options_.min_points ? PlaneUpdateStatus::kContradicted
                                                          : PlaneUpdateStatus::kUnseen;
    return update;
  }
  if (update.through > update.points) {
    update.status = PlaneUpdateStatus::kContradicted;
    return update;
  }
  // Least squares s = offset + g1 a1 + g2 a2; an axis without spread is not fitted.
  const auto n = static_cast<double>(inliers.size());
  Eigen::Vector2d mean_a = Eigen::Vector2d::Zero();
  for (const Sample* sample : inliers) mean_a += Eigen::Vector2d(sample->a1, sample->a2);
  mean_a /= n;
  Eigen::Vector2d spread = Eigen::Vector2d::Zero();
  for (const Sample* sample : inliers) {
    spread += (Eigen::Vector2d(sample->a1, sample->a2) - mean_a).cwiseAbs2();
  }
  spread = (spread / n).cwiseSqrt();
  const bool fit1 = spread.x() >= kMinSpread, fit2 = spread.y() >= kMinSpread;
  Eigen::Matrix3d normal_matrix = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (const Sample* sample : inliers) {
    const Eigen::Vector3d row(1.0, fit1 ? sample->a1 : 0.0, fit2 ? sample->a2 : 0.0);
    normal_matrix += row * row.transpose();
    rhs += row * sample->s;
  }
  if (!fit1) normal_matrix(1, 1) = 1.0;
  if (!fit2) normal_matrix(2, 2) = 1.0;
  const Eigen::Matrix3d inverse = normal_matrix.inverse();
  const Eigen::Vector3d solution = inverse * rhs;
  double rss = 0;
  for (const Sample* sample : inliers) {
    const double r = sample->s - solution[0] - solution[1] * (fit1 ? sample->a1 : 0.0) -
                     solution[2] * (fit2 ? sample->a2 : 0.0);
    rss += r * r;
  }
  const int parameters = 1 + fit1 + fit2;
  const double residual_variance = std::max(1e-4, rss / std::max(1.0, n - parameters));
  const Eigen::Matrix3d covariance = residual_variance * inverse;
  const double offset = solution[0];
  const double offset_sigma =
      std::sqrt(covariance(0, 0) + options_.trajectory_sigma * options_.trajectory_sigma);
  // Slope g1 along e1 is a rotation by -g1 about e2; slope g2 along e2 one by g2 about e1.
  const Eigen::Vector2d tilt(fit2 ? solution[2] : 0.0, fit1 ? -solution[1] : 0.0);
  const double tilt_floor = std::pow(options_.trajectory_tilt_sigma_deg * kRadiansPerDegree, 2);
  const Eigen::Vector2d tilt_sigma(
      fit2 ? std::sqrt(covariance(2, 2) + tilt_floor) : kUnconstrainedTilt,
      fit1 ? std::sqrt(covariance(1, 1) + tilt_floor) : kUnconstrainedTilt);
  update.offset = offset;
  update.offset_sigma = offset_sigma;
  update.tilt = tilt;
  update.tilt_sigma = tilt_sigma;
  const Eigen::Vector3d& normal = record.plane.plane_in_map.normal;
  const Eigen::Vector3d corrected_normal = TiltedNormal(normal, record.e1, tilt);
  const Eigen::Vector3d corrected_centroid = record.plane.centroid + offset * normal;
  update.normal = corrected_normal;
  update.d = -corrected_normal.dot(corrected_centroid);
  const double chi2 = offset * offset / (offset_sigma * offset_sigma) +
                      (tilt.array() / tilt_sigma.array()).square().sum();
  const bool large = std::abs(offset) >= options_.min_offset ||
                     tilt.norm() >= options_.min_tilt_deg * kRadiansPerDegree;
  update.status =
      chi2 > options_.chi2 && large ? PlaneUpdateStatus::kCorrected : PlaneUpdateStatus::kConfirmed;
  return update;
}

}  // namespace planeloc
