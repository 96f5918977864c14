#include "planeloc/map/tensor_voting.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

struct Eigen3 {
  Eigen::Vector3d e1 = Eigen::Vector3d::UnitZ();
  double l1 = 0.0, l2 = 0.0, l3 = 0.0;
};

Eigen3 Decompose(const Eigen::Matrix3d& tensor) {
  Eigen3 out;
  if (!(tensor.trace() > 0.0)) return out;  // no votes: isolated point
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
  solver.computeDirect(tensor);
  const Eigen::Vector3d values = solver.eigenvalues().cwiseMax(0.0);  // ascending
  out.l1 = values(2);
  out.l2 = values(1);
  out.l3 = values(0);
  out.e1 = solver.eigenvectors().col(2).normalized();
  return out;
}

// Writes normal, normalized saliencies and class of point i.
void Store(const Eigen3& eig, std::size_t i, TensorVotingResult& result) {
  result.normals[i] = eig.e1;
  if (eig.l1 <= 0.0) {
    result.stick[i] = result.plate[i] = result.ball[i] = 0.0f;
    result.classes[i] = SaliencyClass::kJunction;
    return;
  }
  result.stick[i] = static_cast<float>((eig.l1 - eig.l2) / eig.l1);
  result.plate[i] = static_cast<float>((eig.l2 - eig.l3) / eig.l1);
  result.ball[i] = static_cast<float>(eig.l3 / eig.l1);
  result.classes[i] = ClassifySaliency(eig.l1, eig.l2, eig.l3);
}

// exp(-x) for x >= 0 by linear interpolation in a table (relative error < 1e-4 for x < 20, 0
// beyond): the vote loops are dominated by exp, and the decay needs no more precision.
class NegExpTable {
 public:
  NegExpTable() {
    for (int i = 0; i <= kSize; ++i) table_[i] = std::exp(-static_cast<double>(i) / kScale);
  }
  double operator()(double x) const {
    const double t = x * kScale;
    if (!(t < kSize)) return 0.0;
    const int i = static_cast<int>(t);
    const double f = t - i;
    return table_[i] + f * (table_[i + 1] - table_[i]);
  }

 private:
  static constexpr int kSize = 20 * 256;
  static constexpr double kScale = 256.0;
  double table_[kSize + 1];
};
const NegExpTable& NegExp() {
  static const NegExpTable table;
  return table;
}

// Upper triangle of a symmetric 3x3 accumulator (xx, xy, xz, yy, yz, zz): half the work of a
// full outer product in the vote loops.
struct SymAccumulator {
  double a[6] = {0, 0, 0, 0, 0, 0};
  void AddOuter(double w, const Eigen::Vector3d& v) {
    a[0] += w * v.x() * v.x();
    a[1] += w * v.x() * v.y();
    a[2] += w * v.x() * v.z();
    a[3] += w * v.y() * v.y();
    a[4] += w * v.y() * v.z();
    a[5] += w * v.z() * v.z();
  }
  void AddIdentity(double w) {
    a[0] += w;
    a[3] += w;
    a[5] += w;
  }
  Eigen::Matrix3d Matrix() const {
    Eigen::Matrix3d m;
    m << a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5];
    return m;
  }
};

// Pass 1: unoriented voters cast (l^2 I - v v^T) w(l) / sigma^2 (see the header).
Eigen::Matrix3d BallTensor(const std::vector<Eigen::Vector3d>& points, const std::int32_t* begin,
                           const std::int32_t* end, std::size_t votee, double inv_sigma2) {
  const NegExpTable& neg_exp = NegExp();
  SymAccumulator tensor;
  const Eigen::Vector3d& x = points[votee];
  for (const std::int32_t* k = begin; k != end; ++k) {
    const Eigen::Vector3d v = x - points[*k];
    const double l2 = v.squaredNorm();
    const double w = neg_exp(l2 * inv_sigma2) * inv_sigma2;
    tensor.AddOuter(-w, v);
    tensor.AddIdentity(w * l2);
  }
  return tensor.Matrix();
}

// Pass 2: voter i casts its normal n_i along the osculating arc. With s = sin(theta) = n.v^, the
// normal rotated by 2 theta simplifies to the reflection n - 2 s v^ (unit, no trigonometry).
Eigen::Matrix3d StickTensor(const std::vector<Eigen::Vector3d>& points, const Neighborhoods& hoods,
                            const std::vector<Eigen::Vector3d>& normals,
                            const std::vector<float>& stick, const std::vector<float>& ball,
                            std::size_t votee, const TensorVotingOptions& options) {
  const NegExpTable& neg_exp = NegExp();
  const double inv_sigma2 = 1.0 / (options.sigma * options.sigma);
  const double curvature_scale = 4.0 * options.curvature_weight * options.sigma * options.sigma;
  const double max_sin = std::sin(options.max_stick_angle_deg * kDegToRad);
  const Eigen::Vector3d& x = points[votee];
  SymAccumulator tensor;
  tensor.AddOuter(stick[votee], normals[votee]);
  for (std::int64_t k = hoods.begin(votee); k < hoods.end(votee); ++k) {
    const std::int32_t voter = hoods.indices[k];
    const Eigen::Vector3d& n = normals[voter];
    const Eigen::Vector3d v = x - points[voter];
    const double l2 = v.squaredNorm();
    if (l2 < 1e-24) {
      tensor.AddOuter(stick[voter], n);
      continue;
    }
    const double inv_l2 = 1.0 / l2;
    const double decay = neg_exp(l2 * inv_sigma2);
    // The voter's ball part votes as a ball (Medioni): without it, clutter whose pass-1 normals
    // are weak but spatially correlated would be smoothed into false surfaces. Unit-free form:
    // ball * decay * (I - v v^T / l^2).
    const double ball_weight = ball[voter] * decay;
    tensor.AddOuter(-ball_weight * inv_l2, v);
    tensor.AddIdentity(ball_weight);
    const double s_times_l = n.dot(v);  // s * l
    const double s2 = s_times_l * s_times_l * inv_l2;
    if (stick[voter] <= 0.0f || s2 > max_sin * max_sin) continue;
    // kappa^2 = 4 s^2 / l^2, so c (sigma kappa)^2 = curvature_scale * s^2 / l^2.
    const double w = stick[voter] * decay * neg_exp(curvature_scale * s2 * inv_l2);
    // n - 2 s v^ = n - 2 (s l) v / l^2.
    const Eigen::Vector3d voted = n - (2.0 * s_times_l * inv_l2) * v;
    tensor.AddOuter(w, voted);
  }
  return tensor.Matrix();
}

template <typename Fn>
void ParallelFor(std::size_t n, Fn&& fn) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 1024),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t i = range.begin(); i != range.end(); ++i) fn(i);
                    });
}

}  // namespace

void TensorVotingOptions::Check() const {
  if (!(sigma > 0.0)) throw OptionsError("TensorVotingOptions.sigma must be > 0 (metres)");
  if (!(radius_factor >= 0.5 && radius_factor <= 5.0)) {
    throw OptionsError("TensorVotingOptions.radius_factor must be in [0.5, 5]");
  }
  if (!(curvature_weight >= 0.0)) {
    throw OptionsError("TensorVotingOptions.curvature_weight must be >= 0");
  }
  if (!(max_stick_angle_deg > 0.0 && max_stick_angle_deg <= 90.0)) {
    throw OptionsError("TensorVotingOptions.max_stick_angle_deg must be in (0, 90]");
  }
  if (stick_passes < 0 || stick_passes > 10) {
    throw OptionsError("TensorVotingOptions.stick_passes must be in [0, 10]");
  }
}

std::string SaliencyClassName(SaliencyClass saliency_class) {
  switch (saliency_class) {
    case SaliencyClass::kSurface:
      return "surface";
    case SaliencyClass::kCurve:
      return "curve";
    case SaliencyClass::kJunction:
      return "junction";
  }
  return "unknown";
}

SaliencyClass ClassifySaliency(double l1, double l2, double l3) {
  const double stick = l1 - l2, plate = l2 - l3, ball = l3;
  if (stick >= plate && stick >= ball && stick > 0.0) return SaliencyClass::kSurface;
  if (plate >= stick && plate >= ball && plate > 0.0) return SaliencyClass::kCurve;
  return SaliencyClass::kJunction;
}

namespace {

TensorVotingResult EmptyResult(std::size_t n) {
  TensorVotingResult result;
  result.normals.assign(n, Eigen::Vector3d::UnitZ());
  result.stick.assign(n, 0.0f);
  result.plate.assign(n, 0.0f);
  result.ball.assign(n, 0.0f);
  result.classes.assign(n, SaliencyClass::kJunction);
  return result;
}

// Ball pass and stick passes; `result` must be EmptyResult(points.size()).
void Vote(const std::vector<Eigen::Vector3d>& points, const TensorVotingOptions& options,
          const Neighborhoods& neighborhoods, TensorVotingResult& result) {
  const double inv_sigma2 = 1.0 / (options.sigma * options.sigma);
  ParallelFor(points.size(), [&](std::size_t i) {
    const std::int32_t* base = neighborhoods.indices.data();
    Store(Decompose(BallTensor(points, base + neighborhoods.begin(i), base + neighborhoods.end(i),
                               i, inv_sigma2)),
          i, result);
  });
  for (int pass = 0; pass < options.stick_passes; ++pass) {
    // Votes read the previous pass only, so the pass is order-independent.
    const std::vector<Eigen::Vector3d> normals = result.normals;
    const std::vector<float> stick = result.stick;
    const std::vector<float> ball = result.ball;
    ParallelFor(points.size(), [&](std::size_t i) {
      Store(Decompose(StickTensor(points, neighborhoods, normals, stick, ball, i, options)), i,
            result);
    });
  }
}

}  // namespace

TensorVotingResult RunTensorVoting(const std::vector<Eigen::Vector3d>& points,
                                   const TensorVotingOptions& options) {
  options.Check();
  const std::size_t n = points.size();
  const std::vector<std::int32_t> order = MortonOrder(points, options.radius());
  std::vector<Eigen::Vector3d> sorted_points(n);
  ParallelFor(n, [&](std::size_t k) { sorted_points[k] = points[order[k]]; });
  Neighborhoods sorted_hoods = FindNeighborhoods(sorted_points, options.radius());
  TensorVotingResult sorted = EmptyResult(n);
  Vote(sorted_points, options, sorted_hoods, sorted);
  std::vector<Eigen::Vector3d>().swap(sorted_points);

  TensorVotingResult result = EmptyResult(n);
  ParallelFor(n, [&](std::size_t k) {
    const auto i = static_cast<std::size_t>(order[k]);
    result.normals[i] = sorted.normals[k];
    result.stick[i] = sorted.stick[k];
    result.plate[i] = sorted.plate[k];
    result.ball[i] = sorted.ball[k];
    result.classes[i] = sorted.classes[k];
  });
  result.neighborhoods = Renumbered(sorted_hoods, InversePermutation(order));
  return result;
}

TensorVotingResult RunTensorVoting(const std::vector<Eigen::Vector3d>& points,
                                   const TensorVotingOptions& options,
                                   Neighborhoods neighborhoods) {
  options.Check();
  if (neighborhoods.size() != points.size()) {
    throw std::invalid_argument("RunTensorVoting: neighbourhoods do not match the points");
  }
  TensorVotingResult result = EmptyResult(points.size());
  Vote(points, options, neighborhoods, result);
  result.neighborhoods = std::move(neighborhoods);
  return result;
}

}  // namespace planeloc
