#include "planeloc/prior/map_registration.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <tuple>

#include "planeloc/optim/robust_gauss_newton.h"
#include "planeloc/prior/registration_voting.h"
#include "planeloc/prior/vehicle_axes.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kInf = std::numeric_limits<double>::infinity();
// Lever arm (metres) that puts rotations in metres for the reported eigenvalues.
constexpr double kLeverArm = 10.0;

// Covariance from point-to-plane information, regularized by a very weak prior (`regularizer_sigma`
// metres, the same over the lever arm in radians) so that an unobserved direction gets a large but
// finite variance instead of leaking rounding noise of a pseudo-inverse into the observed ones.
// Solved in metric units (rotation x lever).
Matrix6d RegularizedCovariance(const Matrix6d& information, double regularizer_sigma) {
  Vector6d scale;
  scale << 1, 1, 1, 1.0 / kLeverArm, 1.0 / kLeverArm, 1.0 / kLeverArm;
  Matrix6d metric = scale.asDiagonal() * information * scale.asDiagonal();
  metric.diagonal().array() += 1.0 / (regularizer_sigma * regularizer_sigma);
  const Matrix6d covariance = metric.ldlt().solve(Matrix6d::Identity());
  return scale.asDiagonal() * covariance * scale.asDiagonal();
}

}  // namespace

// One candidate correction: p_map = rotation (p - pivot) + pivot + shift.
struct MapRegistration::Hypothesis {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  double votes = 0;
  int inliers = 0;
  // Truncated chi2 over all points: (d / sigma)^2, at most inlier_sigmas^2 (also for points on
  // no plane). Differences between hypotheses are log-likelihood ratios.
  double cost = 0;
  double rms = 0, whitened_rms = 0;
  Matrix6d information = Matrix6d::Zero();  // point-to-plane only, (shift, omega) at the pivot
};

struct MapRegistration::SearchSpace {
  Eigen::Vector3d up;         // the map's up (UpDirection of the prior's)
  Eigen::Vector3d pivot;      // the prior's pivot c
  double sigma_vertical = 0;  // metres
  double sigma_heading = 0;   // radians
  ShiftGrid grid;  // horizontal shifts: principal axes of the prior, +-(search_sigmas + margin)
  double horizontal_reach = 0;  // metres, the larger half range of the grid
};

struct MapRegistration::PlaneSets {
  std::vector<int> candidates, grounds, facades;  // indices into planes_
};

struct MapRegistration::PlaneMatch {
  int plane = -1;  // index into planes_
  double sigma = 0;
};

MapRegistration::MapRegistration(const PlaneMap& planes, const MapRegistrationOptions& options)
    : options_(options),
      ground_cos_(std::cos(options.ground_max_tilt_deg * kDegree)),
      facade_sin_(std::sin(options.facade_max_tilt_deg * kDegree)) {
  options_.Check();
  for (const MapPlane& plane : planes.planes) {
    if (plane.area > 0.0 && plane.area < options_.min_plane_area) continue;
    FlatPlane flat;
    flat.id = plane.id;
    flat.plane = plane.plane_in_map;
    flat.sigma = std::hypot(plane.rms, options_.map_sigma);
    flat.ground = plane.kind == "ground";
    std::tie(flat.u, flat.v) = plane.plane_in_map.InPlaneBasis();
    flat.lo = Eigen::Vector3d::Constant(-kInf);
    flat.hi = Eigen::Vector3d::Constant(kInf);
    if (plane.polygon.size() >= 3) {
      flat.lo = flat.hi = plane.polygon.front();
      flat.polygon = plane.polygon;
      for (const Eigen::Vector3d& p : plane.polygon) {
        flat.ring.emplace_back(p.dot(flat.u), p.dot(flat.v));
        flat.lo = flat.lo.cwiseMin(p);
        flat.hi = flat.hi.cwiseMax(p);
      }
    }
    planes_.push_back(std::move(flat));
  }
}

Eigen::Vector3d MapRegistration::UpDirection(const Eigen::Vector3d& hint) const {
  const Eigen::Vector3d h = hint.normalized();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const FlatPlane& plane : planes_) {
    if (!plane.ground) continue;
    const Eigen::Vector3d n =
        plane.plane.normal.dot(h) >= 0 ? plane.plane.normal : Eigen::Vector3d(-plane.plane.normal);
    // Area weighting through the outline's box would favour long thin planes; the ground planes
    // of a street map are all nearly parallel, so a plain mean is enough.
    if (n.dot(h) > ground_cos_) sum += n;
  }
  return sum.norm() > 0.5 ? sum.normalized() : h;
}

bool MapRegistration::NearOutline(const FlatPlane& plane, const Eigen::Vector3d& point,
                                  double margin) const {
  if (plane.ring.size() < 3) return true;
  // Quick rejection: the point's projection outside the outline's box grown by the margin.
  const Eigen::Vector3d projected = plane.plane.Project(point);
  if ((projected.array() < plane.lo.array() - margin).any() ||
      (projected.array() > plane.hi.array() + margin).any()) {
    return false;
  }
  const Eigen::Vector2d q(point.dot(plane.u), point.dot(plane.v));
  return InsideOrNearPolygon2d(plane.ring, q, margin);
}

std::vector<RegistrationPoint> MapRegistration::Subsample(
    const std::vector<RegistrationPoint>& all_points) const {
  // A deterministic subsample: every k-th point.
  std::vector<RegistrationPoint> points;
  const std::size_t stride =
      std::max<std::size_t>(1, (all_points.size() + options_.max_points - 1) / options_.max_points);
  for (std::size_t i = 0; i < all_points.size(); i += stride) {
    if (all_points[i].point_in_world.allFinite()) points.push_back(all_points[i]);
  }
  return points;
}

MapRegistration::SearchSpace MapRegistration::PriorSearchSpace(
    const RegistrationPrior& prior) const {
  SearchSpace search;
  search.up = UpDirection(prior.up_in_world);
  search.pivot = prior.pivot_in_world;
  const Eigen::Vector3d& up = search.up;
  const Eigen::Matrix3d shift_cov = prior.covariance.topLeftCorner<3, 3>();
  const Eigen::Matrix3d angle_cov = prior.covariance.bottomRightCorner<3, 3>();
  search.sigma_vertical = std::sqrt(std::max(0.0, up.dot(shift_cov * up)));
  search.sigma_heading = std::sqrt(std::max(0.0, up.dot(angle_cov * up)));
  // Horizontal search axes: principal axes of the prior's horizontal shift covariance.
  const Eigen::Vector3d e1 = AnyPerpendicular(up);
  const Eigen::Vector3d e2 = up.cross(e1);
  Eigen::Matrix<double, 3, 2> basis;
  basis << e1, e2;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> horizontal(basis.transpose() * shift_cov *
                                                                  basis);
  ShiftGrid& grid = search.grid;
  for (int k = 0; k < 2; ++k) {
    grid.axis[k] = basis * horizontal.eigenvectors().col(k);
    grid.half_range[k] =
        options_.search_sigmas * std::sqrt(std::max(0.0, horizontal.eigenvalues()(k))) +
        options_.search_margin;
  }
  grid.cell = std::max({options_.shift_cell, 2.0 * grid.half_range[0] / (options_.max_cells - 1),
                        2.0 * grid.half_range[1] / (options_.max_cells - 1)});
  for (int k = 0; k < 2; ++k) {
    grid.cells[k] = static_cast<int>(std::ceil(2.0 * grid.half_range[k] / grid.cell)) + 1;
  }
  search.horizontal_reach = std::max(grid.half_range[0], grid.half_range[1]);
  return search;
}

MapRegistration::PlaneSets MapRegistration::ReachablePlanes(
    const std::vector<RegistrationPoint>& points, const SearchSpace& search) const {
  Eigen::Vector3d lo = points.front().point_in_world, hi = lo;
  double lever = 0;
  for (const RegistrationPoint& p : points) {
    lo = lo.cwiseMin(p.point_in_world);
    hi = hi.cwiseMax(p.point_in_world);
    lever = std::max(lever, (p.point_in_world - search.pivot).norm());
  }
  const double reach =
      search.horizontal_reach +
      options_.search_sigmas * (search.sigma_vertical + search.sigma_heading * lever) +
      options_.reach_margin;
  PlaneSets sets;
  for (int i = 0; i < static_cast<int>(planes_.size()); ++i) {
    const FlatPlane& plane = planes_[i];
    if ((plane.hi.array() < lo.array() - reach).any() ||
        (plane.lo.array() > hi.array() + reach).any()) {
      continue;
    }
    sets.candidates.push_back(i);
    const double vertical = std::abs(plane.plane.normal.dot(search.up));
    if (vertical > ground_cos_) sets.grounds.push_back(i);
    if (vertical < facade_sin_) sets.facades.push_back(i);
  }
  return sets;
}

double MapRegistration::VoteHeight(const std::vector<RegistrationPoint>& points,
                                   const SearchSpace& search, const std::vector<int>& grounds,
                                   std::vector<bool>& near_ground) const {
  const double vertical_range =
      options_.search_sigmas * search.sigma_vertical + options_.vertical_search_margin;
  const double bin = options_.vertical_bin;
  std::vector<double> ground_votes;
  near_ground.assign(points.size(), false);
  for (std::size_t i = 0; i < points.size(); ++i) {
    for (const int g : grounds) {
      const FlatPlane& plane = planes_[g];
      const Eigen::Vector3d& p = points[i].point_in_world;
      if (!NearOutline(plane, p, search.horizontal_reach)) continue;
      const double shift = -plane.plane.SignedDistance(p) / plane.plane.normal.dot(search.up);
      if (std::abs(shift) > vertical_range + 0.5 * bin) continue;
      ground_votes.push_back(shift);
      near_ground[i] = true;
    }
  }
  return VoteVerticalShift(ground_votes, vertical_range, bin);
}

std::vector<Eigen::Vector3d> MapRegistration::FacadeVoters(
    const std::vector<RegistrationPoint>& points, const SearchSpace& search,
    const std::vector<int>& grounds, const std::vector<bool>& near_ground,
    double vertical_shift) const {
  // Points on the ground (after the vertical shift) vote for no facade.
  std::vector<Eigen::Vector3d> voters;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p = points[i].point_in_world + vertical_shift * search.up;
    bool on_ground = false;
    for (const int g : grounds) {
      if (near_ground[i] && std::abs(planes_[g].plane.SignedDistance(p)) < options_.ground_band) {
        on_ground = true;
      }
    }
    if (!on_ground) voters.push_back(p);
  }
  return voters;
}

std::vector<MapRegistration::Hypothesis> MapRegistration::VoteHeadingAndShiftHypotheses(
    const std::vector<Eigen::Vector3d>& facade_voters, const SearchSpace& search,
    const std::vector<int>& facades, double vertical_shift) const {
  const double sigma_heading = search.sigma_heading;
  const int num_headings =
      sigma_heading > 0 ? std::max(1, std::min(options_.max_headings,
                                               static_cast<int>(std::ceil(
                                                   2.0 * options_.search_sigmas * sigma_heading /
                                                   (options_.heading_step_deg * kDegree))) +
                                                   1))
                        : 1;
  std::vector<double> headings;
  for (int k = 0; k < num_headings; ++k) {
    headings.push_back(num_headings == 1 ? 0.0
                                         : -options_.search_sigmas * sigma_heading +
                                               2.0 * options_.search_sigmas * sigma_heading * k /
                                                   (num_headings - 1));
  }
  std::vector<HoughFacade> hough_facades;
  for (const int f : facades) {
    hough_facades.push_back(MakeHoughFacade(planes_[f].plane, planes_[f].polygon, search.up));
  }
  HoughOptions hough_options;
  hough_options.outline_margin = options_.outline_margin;
  hough_options.peaks_per_heading = options_.peaks_per_heading;
  const std::vector<HeadingShiftPeak> peaks = VoteHeadingAndShift(
      facade_voters, search.pivot, search.up, hough_facades, headings, search.grid, hough_options);

  // Distinct peaks, plus the prior's mean (the answer when no facade votes).
  std::vector<Hypothesis> hypotheses;
  auto add_hypothesis = [&](double heading, const Eigen::Vector3d& shift, double votes) {
    for (const Hypothesis& h : hypotheses) {
      const double angle = std::abs(Eigen::AngleAxisd(h.rotation).angle() - std::abs(heading));
      if ((h.shift - shift).norm() < options_.duplicate_peak_shift &&
          angle < options_.duplicate_peak_angle_deg * kDegree) {
        return;
      }
    }
    Hypothesis h;
    h.rotation = Eigen::AngleAxisd(heading, search.up).toRotationMatrix();
    h.shift = shift;
    h.votes = votes;
    hypotheses.push_back(h);
  };
  for (const HeadingShiftPeak& peak : peaks) {
    if (static_cast<int>(hypotheses.size()) >= options_.num_hypotheses) break;
    add_hypothesis(peak.heading, peak.shift_xy + vertical_shift * search.up, peak.votes);
  }
  add_hypothesis(0.0, vertical_shift * search.up, 0.0);
  return hypotheses;
}

void MapRegistration::AssociatePlanes(const std::vector<RegistrationPoint>& points,
                                      const Eigen::Vector3d& pivot,
                                      const std::vector<int>& candidates,
                                      const Hypothesis& hypothesis, double gate,
                                      std::vector<PlaneMatch>& matches) const {
  const Eigen::Vector3d& c = pivot;
  const double floor2 = options_.min_point_sigma * options_.min_point_sigma;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d p =
        hypothesis.rotation * (points[i].point_in_world - c) + c + hypothesis.shift;
    matches[i] = PlaneMatch{};
    double best = kInf;
    for (const int index : candidates) {
      const FlatPlane& plane = planes_[index];
      const double sigma = std::sqrt(std::max(floor2, points[i].sigma * points[i].sigma) +
                                     plane.sigma * plane.sigma);
      const double distance = std::abs(plane.plane.SignedDistance(p));
      if (distance > gate + options_.inlier_sigmas * sigma || distance >= best) continue;
      if (!NearOutline(plane, p, options_.outline_margin)) continue;
      best = distance;
      matches[i] = PlaneMatch{index, sigma};
    }
  }
}

void MapRegistration::Refine(const std::vector<RegistrationPoint>& points,
                             const RegistrationPrior& prior, const std::vector<int>& candidates,
                             Hypothesis& hypothesis) const {
  const Eigen::Vector3d& c = prior.pivot_in_world;
  // Prior information; a zero sigma (exact DoF) becomes a very stiff one.
  Matrix6d prior_covariance = prior.covariance;
  prior_covariance.diagonal().array() += options_.prior_variance_floor;
  const Matrix6d prior_information = prior_covariance.inverse();

  std::vector<PlaneMatch> matches(points.size());
  const auto linearize = [&](int iteration, HuberNormalEquations<6>& equations) {
    AssociatePlanes(points, c, candidates, hypothesis, options_.association_gates[iteration],
                    matches);
    for (std::size_t i = 0; i < points.size(); ++i) {
      if (matches[i].plane < 0) continue;
      const Plane& plane = planes_[matches[i].plane].plane;
      const Eigen::Vector3d q = hypothesis.rotation * (points[i].point_in_world - c);
      const double r = plane.SignedDistance(q + c + hypothesis.shift) / matches[i].sigma;
      Eigen::Matrix<double, 1, 6> j;
      j.head<3>() = plane.normal.transpose();
      j.tail<3>() = -plane.normal.transpose() * Hat(q);
      j /= matches[i].sigma;
      equations.Add(r, j);
    }
    Vector6d xi;
    xi.head<3>() = hypothesis.shift;
    xi.tail<3>() = LogSO3(hypothesis.rotation);
    return xi;
  };
  const auto apply = [&](const Vector6d& step) {
    hypothesis.shift += step.head<3>();
    hypothesis.rotation = ExpSO3(step.tail<3>()) * hypothesis.rotation;
  };
  RobustGaussNewton<6>(static_cast<int>(options_.association_gates.size()), options_.huber_sigmas,
                       prior_information, linearize, apply);

  // Score with the final association.
  AssociatePlanes(points, c, candidates, hypothesis, 0.0, matches);
  Score(points, c, matches, hypothesis);
}

void MapRegistration::Score(const std::vector<RegistrationPoint>& points,
                            const Eigen::Vector3d& pivot, const std::vector<PlaneMatch>& matches,
                            Hypothesis& hypothesis) const {
  const Eigen::Vector3d& c = pivot;
  hypothesis.inliers = 0;
  hypothesis.information.setZero();
  double sum2 = 0, whitened2 = 0;
  const double truncation2 = options_.inlier_sigmas * options_.inlier_sigmas;
  hypothesis.cost = truncation2 * static_cast<double>(points.size());
  const double inflation2 = options_.noise_inflation * options_.noise_inflation;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (matches[i].plane < 0) continue;
    const Plane& plane = planes_[matches[i].plane].plane;
    const Eigen::Vector3d q = hypothesis.rotation * (points[i].point_in_world - c);
    const double distance = plane.SignedDistance(q + c + hypothesis.shift);
    ++hypothesis.inliers;
    sum2 += distance * distance;
    whitened2 += distance * distance / (matches[i].sigma * matches[i].sigma);
    hypothesis.cost += distance * distance / (matches[i].sigma * matches[i].sigma) - truncation2;
    Eigen::Matrix<double, 1, 6> j;
    j.head<3>() = plane.normal.transpose();
    j.tail<3>() = -plane.normal.transpose() * Hat(q);
    hypothesis.information +=
        j.transpose() * j / (matches[i].sigma * matches[i].sigma * inflation2);
  }
  hypothesis.rms = hypothesis.inliers > 0 ? std::sqrt(sum2 / hypothesis.inliers) : kInf;
  hypothesis.whitened_rms =
      hypothesis.inliers > 0 ? std::sqrt(whitened2 / hypothesis.inliers) : kInf;
}

void MapRegistration::RefineAndRank(const std::vector<RegistrationPoint>& points,
                                    const RegistrationPrior& prior,
                                    const std::vector<int>& candidates,
                                    std::vector<Hypothesis>& hypotheses) const {
  for (Hypothesis& h : hypotheses) Refine(points, prior, candidates, h);
  std::stable_sort(hypotheses.begin(), hypotheses.end(),
                   [](const Hypothesis& a, const Hypothesis& b) { return a.cost < b.cost; });
}

std::array<Eigen::Vector3d, kNumDofs> MapRegistration::ConditionAtCamera(
    const Hypothesis& best, const SearchSpace& search, const Rigid3d& world_from_camera,
    RegistrationResult& result) const {
  const Eigen::Vector3d& c = search.pivot;
  // Conditioning at the current camera, in the map frame of the best hypothesis: a change
  // (d_shift, d_omega) moves the camera by d_shift - [R (camera - c)]x d_omega.
  const Eigen::Vector3d camera = world_from_camera.translation;
  const VehicleAxes axes =
      AxesAt(best.rotation * (world_from_camera.rotation * Eigen::Vector3d::UnitZ()),
             best.rotation * search.up);
  Matrix6d to_camera = Matrix6d::Identity();
  to_camera.topRightCorner<3, 3>() = -Hat(best.rotation * (camera - c));
  const Matrix6d covariance = to_camera *
                              RegularizedCovariance(best.information, options_.regularizer_sigma) *
                              to_camera.transpose();
  // The same change of pivot for the information (x_camera = to_camera x_pivot), then the
  // vehicle axes; and the best hypothesis as a camera shift and a rotation in those axes.
  Matrix6d from_camera = Matrix6d::Identity();
  from_camera.topRightCorner<3, 3>() = Hat(best.rotation * (camera - c));
  result.vehicle_axes.row(0) = axes.along.transpose();
  result.vehicle_axes.row(1) = axes.lateral.transpose();
  result.vehicle_axes.row(2) = axes.up.transpose();
  Matrix6d to_vehicle = Matrix6d::Zero();
  to_vehicle.topLeftCorner<3, 3>() = result.vehicle_axes;
  to_vehicle.bottomRightCorner<3, 3>() = result.vehicle_axes;
  result.information_at_camera = to_vehicle * from_camera.transpose() * best.information *
                                 from_camera * to_vehicle.transpose();
  result.camera_in_world = camera;
  result.correction_at_camera.head<3>() =
      result.vehicle_axes * (best.rotation * (camera - c) + c + best.shift - camera);
  result.correction_at_camera.tail<3>() = result.vehicle_axes * LogSO3(best.rotation);
  result.camera_position_covariance = covariance.topLeftCorner<3, 3>();
  const std::array<Eigen::Vector3d, kNumDofs> named = {axes.along, axes.lateral, axes.up,
                                                       axes.along, axes.lateral, axes.up};
  for (int dof = 0; dof < kNumDofs; ++dof) {
    const Eigen::Matrix3d block =
        dof < 3 ? covariance.topLeftCorner<3, 3>() : covariance.bottomRightCorner<3, 3>();
    const double sigma = std::sqrt(std::max(0.0, named[dof].dot(block * named[dof])));
    result.dof_sigma[dof] =
        sigma > (dof < 3 ? options_.unobserved_shift_sigma : options_.unobserved_angle_sigma)
            ? kInf
            : sigma;
    const double limit = dof < 3       ? options_.max_dof_sigma
                         : dof == kYaw ? options_.max_dof_sigma_deg * kDegree
                                       : options_.max_tilt_sigma_deg * kDegree;
    result.constrained[dof] = sigma <= limit;
  }
  Matrix6d metric = best.information;
  metric.bottomRightCorner<3, 3>() /= kLeverArm * kLeverArm;
  metric.topRightCorner<3, 3>() /= kLeverArm;
  metric.bottomLeftCorner<3, 3>() /= kLeverArm;
  result.information_eigenvalues = Eigen::SelfAdjointEigenSolver<Matrix6d>(metric).eigenvalues();
  return named;
}

double MapRegistration::MarginOverDistinct(const std::vector<Hypothesis>& ranked,
                                           const Eigen::Vector3d& pivot,
                                           const Eigen::Vector3d& camera,
                                           const std::array<Eigen::Vector3d, kNumDofs>& named,
                                           const std::array<bool, kNumDofs>& constrained) const {
  const Eigen::Vector3d& c = pivot;
  const Hypothesis& best = ranked.front();
  const auto apply = [&](const Hypothesis& h, const Eigen::Vector3d& x) {
    return Eigen::Vector3d(h.rotation * (x - c) + c + h.shift);
  };
  double second = kInf;
  for (std::size_t k = 1; k < ranked.size(); ++k) {
    const Hypothesis& other = ranked[k];
    const Eigen::Vector3d dt = apply(other, camera) - apply(best, camera);
    const Eigen::Vector3d dr = LogSO3(other.rotation * best.rotation.transpose());
    bool distinct = false;
    for (int dof = 0; dof < kNumDofs; ++dof) {
      if (!constrained[dof]) continue;
      const double difference = std::abs((dof < 3 ? dt : dr).dot(named[dof]));
      distinct |= dof < 3 ? difference > options_.distinct_shift
                          : difference > options_.distinct_angle_deg * kDegree;
    }
    if (distinct) second = std::min(second, other.cost);
  }
  // The cost difference to the best distinct hypothesis, deflated like the information: a
  // chi2-like log-likelihood ratio that ground points (which fit every hypothesis of the right
  // height) do not dilute.
  return (second - best.cost) / (options_.noise_inflation * options_.noise_inflation);
}

void MapRegistration::Verdict(const Hypothesis& best, const Eigen::Vector3d& pivot,
                              RegistrationResult& result) const {
  const Eigen::Vector3d& c = pivot;
  const bool all_but_along = result.constrained[kLateral] && result.constrained[kVertical] &&
                             result.constrained[kRoll] && result.constrained[kPitch] &&
                             result.constrained[kYaw];
  if (result.inlier_ratio < options_.min_inlier_ratio || best.inliers < options_.min_points / 2) {
    result.reason = "few points on planes (" + std::to_string(best.inliers) + " of " +
                    std::to_string(result.points) + ")";
  } else if (result.whitened_rms > options_.max_whitened_rms) {
    result.reason = "point-to-plane residuals too large for the points' sigmas";
  } else if (result.margin < options_.min_margin) {
    result.reason = "ambiguous: a distinct hypothesis fits almost as well";
  } else if (!all_but_along) {
    result.reason = "the planes in view do not constrain";
    for (int dof = kLateral; dof < kNumDofs; ++dof) {
      if (!result.constrained[dof]) result.reason += std::string(" ") + RegistrationDofName(dof);
    }
  } else {
    result.lock = result.constrained[kAlongTrack] ? MapLock::kLocked : MapLock::kPartial;
    if (result.lock == MapLock::kPartial) result.reason = "along-track not observed";
    result.map_from_world = Rigid3d(best.rotation, c + best.shift - best.rotation * c);
  }
}

RegistrationResult MapRegistration::Register(const std::vector<RegistrationPoint>& all_points,
                                             const RegistrationPrior& prior,
                                             const Rigid3d& world_from_camera) const {
  RegistrationResult result;
  for (double& sigma : result.dof_sigma) sigma = kInf;
  const std::vector<RegistrationPoint> points = Subsample(all_points);
  result.points = static_cast<int>(points.size());
  if (result.points < options_.min_points) {
    result.reason = "too little structure (" + std::to_string(result.points) + " points, need " +
                    std::to_string(options_.min_points) + ")";
    return result;
  }
  if (planes_.empty()) {
    result.reason = "the plane map has no usable plane";
    return result;
  }
  const SearchSpace search = PriorSearchSpace(prior);
  const PlaneSets planes = ReachablePlanes(points, search);
  if (planes.candidates.empty()) {
    result.reason = "no plane of the map within reach of the structure";
    return result;
  }

  // Voting (docs/map-registration.md, steps 1 and 2): height, then heading x horizontal shift.
  std::vector<bool> near_ground;
  const double vertical_shift = VoteHeight(points, search, planes.grounds, near_ground);
  const std::vector<Eigen::Vector3d> facade_voters =
      FacadeVoters(points, search, planes.grounds, near_ground, vertical_shift);
  std::vector<Hypothesis> hypotheses =
      VoteHeadingAndShiftHypotheses(facade_voters, search, planes.facades, vertical_shift);

  // Refinement and scoring (steps 3 and 4); the best first.
  RefineAndRank(points, prior, planes.candidates, hypotheses);
  result.hypotheses = static_cast<int>(hypotheses.size());
  const Hypothesis& best = hypotheses.front();
  const Eigen::Vector3d& c = search.pivot;
  result.candidate_map_from_world = Rigid3d(best.rotation, c + best.shift - best.rotation * c);
  result.inliers = best.inliers;
  result.inlier_ratio = static_cast<double>(best.inliers) / result.points;
  result.rms = best.rms;
  result.whitened_rms = best.whitened_rms;

  // Conditioning, margin and the verdict (acceptance).
  const std::array<Eigen::Vector3d, kNumDofs> named =
      ConditionAtCamera(best, search, world_from_camera, result);
  result.margin =
      MarginOverDistinct(hypotheses, c, world_from_camera.translation, named, result.constrained);
  Verdict(best, c, result);
  return result;
}

}  // namespace planeloc
