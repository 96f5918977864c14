#include "planeloc/map/plane_uncertainty.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <unordered_map>
#include <utility>

namespace planeloc {
namespace {

// The factors of PlaneSigmaFromSpread, calibrated on the simulator's GT planes of the clean and
// noisy-pose maps of small seeds 3, 11 and 21 and validated on seed 7 (docs/map.md, "Plane
// uncertainty": the smallest factors that cover >= 90 % of the offset errors within 2 sigma and
// >= 99 % within 3 sigma in both kinds of map).
constexpr double kCorrelatedGain = 3.0;  // on cell_spread, for the offset and the tilt
constexpr double kSlabGain = 0.2;        // on rms: where in its slab the surface lies
constexpr double kOffsetFloor = 0.001;   // metres
constexpr double kNormalFloor = 1.0e-4;  // radians

std::int64_t CellKey(double a, double b, double cell_size) {
  const auto ia = static_cast<std::int64_t>(std::floor(a / cell_size));
  const auto ib = static_cast<std::int64_t>(std::floor(b / cell_size));
  return (ia << 32) ^ (ib & 0xffffffffLL);
}

// In-plane geometry and cell structure of `members` about `plane` (points and rms filled by the
// caller).
PlaneSpread MeasureSpread(const std::vector<Eigen::Vector3d>& members, const Plane& plane,
                          int min_cell_members) {
  PlaneSpread spread;
  // Named copies, not a structured binding: clang 14 cannot capture one in a lambda.
  const std::pair<Eigen::Vector3d, Eigen::Vector3d> basis = plane.InPlaneBasis();
  const Eigen::Vector3d u = basis.first, v = basis.second;
  const auto flat = [&](const Eigen::Vector3d& p) { return Eigen::Vector2d(p.dot(u), p.dot(v)); };
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : members) mean += flat(p);
  mean /= static_cast<double>(members.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const auto& p : members)
    scatter.noalias() += (flat(p) - mean) * (flat(p) - mean).transpose();
  // Eigenvalues ascending: column 0 is the minor axis, column 1 the major one.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(scatter /
                                                              static_cast<double>(members.size()));
  const Eigen::Matrix2d axes = solver.eigenvectors();
  spread.major_axis = (axes(0, 1) * u + axes(1, 1) * v).normalized();
  spread.deviation = solver.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector2d hi = -lo;
  struct Cell {
    int count = 0;
    double residual_sum = 0;
    double residual_squares = 0;
  };
  std::unordered_map<std::int64_t, Cell> cells;
  for (const auto& p : members) {
    const Eigen::Vector2d f = axes.transpose() * (flat(p) - mean);
    lo = lo.cwiseMin(f);
    hi = hi.cwiseMax(f);
    Cell& cell = cells[CellKey(f.x(), f.y(), kPlaneSpreadCellSize)];
    const double residual = plane.SignedDistance(p);
    ++cell.count;
    cell.residual_sum += residual;
    cell.residual_squares += residual * residual;
  }
  spread.extent = hi - lo;
  // The mean residual of a cell also carries the white noise of its members (variance s^2 / n):
  // subtracting the within-cell estimate of it leaves the structure shared by the cell.
  double cell_squares = 0;
  for (const auto& [key, cell] : cells) {
    if (cell.count < min_cell_members) continue;
    const double n = cell.count;
    const double cell_mean = cell.residual_sum / n;
    const double within = n > 1 ? (cell.residual_squares - n * cell_mean * cell_mean) / (n - 1) : 0;
    cell_squares += cell_mean * cell_mean - std::max(0.0, within) / n;
    ++spread.cells;
  }
  cell_squares = std::max(0.0, cell_squares);
  if (spread.cells > 0) spread.cell_spread = std::sqrt(cell_squares / spread.cells);
  return spread;
}

}  // namespace

PlaneSpread MeasurePlaneSpread(const std::vector<Eigen::Vector3d>& points,
                               const std::vector<int>& inliers, const Plane& plane) {
  if (inliers.size() < 3) throw std::invalid_argument("MeasurePlaneSpread: fewer than 3 inliers");
  std::vector<Eigen::Vector3d> members;
  members.reserve(inliers.size());
  double squares = 0;
  for (const int i : inliers) {
    members.push_back(points[i]);
    squares += plane.SignedDistance(points[i]) * plane.SignedDistance(points[i]);
  }
  PlaneSpread spread = MeasureSpread(members, plane, kMinCellPoints);
  spread.points = static_cast<int>(members.size());
  spread.rms = std::sqrt(squares / spread.points);
  return spread;
}

PlaneSpread MeasureSampledPlaneSpread(const std::vector<Eigen::Vector3d>& samples, int points,
                                      double rms, const Plane& plane) {
  if (samples.empty() || points < 3) {
    throw std::invalid_argument("MeasureSampledPlaneSpread: no samples or fewer than 3 points");
  }
  PlaneSpread spread = MeasureSpread(samples, plane, 1);
  spread.points = points;
  spread.rms = rms;
  return spread;
}

PlaneSigma PlaneSigmaFromSpread(const PlaneSpread& spread) {
  PlaneSigma sigma;
  sigma.major_axis = spread.major_axis;
  const double n = std::max(1, spread.points);
  const double white2 = spread.rms * spread.rms / n;
  // Errors shared by the points (they do not average out): the registration's, seen as structure
  // between cells, and the slab's, the part of its thickness a single surface cannot be told from.
  const double shared2 =
      std::pow(kCorrelatedGain * spread.cell_spread, 2) + std::pow(kSlabGain * spread.rms, 2);
  sigma.offset = std::sqrt(white2 + shared2 + kOffsetFloor * kOffsetFloor);
  // A rotation about the major axis tilts the plane across the minor one: the inliers' spread
  // along the minor axis holds it (index 0), the spread along the major axis holds the other one.
  // A shared error that differs between the two ends tilts the plane by about shared / half extent.
  for (int k = 0; k < 2; ++k) {
    const double deviation = std::max(spread.deviation[k], 1e-3);
    const double half_extent = std::max(spread.extent[k] / 2.0, 1e-3);
    sigma.normal[k] =
        std::sqrt(white2 / (deviation * deviation) + shared2 / (half_extent * half_extent) +
                  kNormalFloor * kNormalFloor);
  }
  return sigma;
}

}  // namespace planeloc
