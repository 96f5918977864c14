#include "planeloc/map/tensor_voting.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "planeloc/map/fast_exp.h"
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

// Per-votee scratch: the votee-to-voter vectors and voter attributes of one neighbourhood in
// structure-of-arrays float form, so that the vote loops below vectorize.
struct VoterBatch {
  std::vector<float> vx, vy, vz, nx, ny, nz, stick, ball;
  void Resize(std::size_t n) {
    for (auto* a : {&vx, &vy, &vz, &nx, &ny, &nz, &stick, &ball}) {
      if (a->size() < n) a->resize(n);
    }
  }
};

// Upper triangle (xx, xy, xz, yy, yz, zz) plus an isotropic part: tensor = sym + iso * I.
struct VoteSums {
  float xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0, iso = 0;
  Eigen::Matrix3d Matrix() const {
    Eigen::Matrix3d m;
    m << xx + iso, xy, xz, xy, yy + iso, yz, xz, yz, zz + iso;
    return m;
  }
};

// Loads the vectors v = x_votee - x_voter (computed in double, then rounded: the map may be
// kilometres from its origin) of votee i's neighbours into `batch`.
std::size_t GatherOffsets(const std::vector<Eigen::Vector3d>& points, const Neighborhoods& hoods,
                          std::size_t i, VoterBatch& batch) {
  const std::size_t k = static_cast<std::size_t>(hoods.end(i) - hoods.begin(i));
  batch.Resize(k);
  const Eigen::Vector3d& x = points[i];
  const std::int32_t* voters = hoods.indices.data() + hoods.begin(i);
  for (std::size_t j = 0; j < k; ++j) {
    const Eigen::Vector3d v = x - points[static_cast<std::size_t>(voters[j])];
    batch.vx[j] = static_cast<float>(v.x());
    batch.vy[j] = static_cast<float>(v.y());
    batch.vz[j] = static_cast<float>(v.z());
  }
  return k;
}

// Pass 1: unoriented voters cast (l^2 I - v v^T) w(l) / sigma^2 (see the header).
Eigen::Matrix3d BallTensor(const VoterBatch& batch, std::size_t k, float inv_sigma2) {
  float xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0, iso = 0;
  const float* vx = batch.vx.data();
  const float* vy = batch.vy.data();
  const float* vz = batch.vz.data();
#pragma omp simd reduction(+ : xx, xy, xz, yy, yz, zz, iso)
  for (std::size_t j = 0; j < k; ++j) {
    const float x = vx[j], y = vy[j], z = vz[j];
    const float l2 = x * x + y * y + z * z;
    const float w = FastNegExp(l2 * inv_sigma2) * inv_sigma2;
    xx -= w * x * x;
    xy -= w * x * y;
    xz -= w * x * z;
    yy -= w * y * y;
    yz -= w * y * z;
    zz -= w * z * z;
    iso += w * l2;
  }
  return VoteSums{xx, xy, xz, yy, yz, zz, iso}.Matrix();
}

struct StickParams {
  float inv_sigma2;
  float curvature_scale;  // 4 c sigma^2: c (sigma kappa)^2 = curvature_scale * s^2 / l^2
  float max_sin2;         // sin^2 of the largest angle between the voter's plane and v
};

// Pass 2: voter j casts its normal n_j along the osculating arc. With s = sin(theta) = n.v^, the
// normal rotated by 2 theta simplifies to the reflection n - 2 s v^ (unit, no trigonometry). The
// voter's ball part votes as a ball (Medioni): without it, clutter whose pass-1 normals are weak
// but spatially correlated would be smoothed into false surfaces. Unit-free form:
// ball * decay * (I - v v^T / l^2). A duplicate point (l = 0) casts its own stick.
Eigen::Matrix3d StickTensor(const VoterBatch& batch, std::size_t k, const StickParams& params) {
  float xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0, iso = 0;
  const float* vx = batch.vx.data();
  const float* vy = batch.vy.data();
  const float* vz = batch.vz.data();
  const float* nx = batch.nx.data();
  const float* ny = batch.ny.data();
  const float* nz = batch.nz.data();
  const float* stick = batch.stick.data();
  const float* ball = batch.ball.data();
#pragma omp simd reduction(+ : xx, xy, xz, yy, yz, zz, iso)
  for (std::size_t j = 0; j < k; ++j) {
    const float x = vx[j], y = vy[j], z = vz[j];
    const float l2 = x * x + y * y + z * z;
    // Not `l2 > 0 ? 1 / l2 : 0`: a division under a condition cannot be if-converted (it may
    // trap), and the loop would not vectorize.
    const float inv_l2 = (l2 > 1e-20f ? 1.0f : 0.0f) / std::max(l2, 1e-20f);
    const float decay = FastNegExp(l2 * params.inv_sigma2);
    const float s_times_l = nx[j] * x + ny[j] * y + nz[j] * z;
    const float s2 = s_times_l * s_times_l * inv_l2;
    const float in_cone = s2 <= params.max_sin2 ? 1.0f : 0.0f;
    const float w = in_cone * stick[j] * decay * FastNegExp(params.curvature_scale * s2 * inv_l2);
    const float c = 2.0f * s_times_l * inv_l2;  // n - 2 s v^ = n - 2 (s l) v / l^2
    const float ux = nx[j] - c * x, uy = ny[j] - c * y, uz = nz[j] - c * z;
    const float ball_weight = ball[j] * decay;
    const float q = ball_weight * inv_l2;
    xx += w * ux * ux - q * x * x;
    xy += w * ux * uy - q * x * y;
    xz += w * ux * uz - q * x * z;
    yy += w * uy * uy - q * y * y;
    yz += w * uy * uz - q * y * z;
    zz += w * uz * uz - q * z * z;
    iso += ball_weight;
  }
  return VoteSums{xx, xy, xz, yy, yz, zz, iso}.Matrix();
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
  if (max_neighbors < 0) throw OptionsError("TensorVotingOptions.max_neighbors must be >= 0");
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
  const std::size_t n = points.size();
  const double inv_sigma2 = 1.0 / (options.sigma * options.sigma);
  tbb::enumerable_thread_specific<VoterBatch> batches;
  ParallelFor(n, [&](std::size_t i) {
    VoterBatch& batch = batches.local();
    const std::size_t k = GatherOffsets(points, neighborhoods, i, batch);
    Store(Decompose(BallTensor(batch, k, static_cast<float>(inv_sigma2))), i, result);
  });
  const double max_sin = std::sin(options.max_stick_angle_deg * kDegToRad);
  const StickParams params{
      static_cast<float>(inv_sigma2),
      static_cast<float>(4.0 * options.curvature_weight * options.sigma * options.sigma),
      static_cast<float>(max_sin * max_sin)};
  std::vector<float> normals(3 * n);
  for (int pass = 0; pass < options.stick_passes; ++pass) {
    // Votes read the previous pass only, so the pass is order-independent.
    ParallelFor(n, [&](std::size_t i) {
      for (int a = 0; a < 3; ++a) normals[3 * i + a] = static_cast<float>(result.normals[i](a));
    });
    const std::vector<float> stick = result.stick;
    const std::vector<float> ball = result.ball;
    ParallelFor(n, [&](std::size_t i) {
      VoterBatch& batch = batches.local();
      const std::size_t k = GatherOffsets(points, neighborhoods, i, batch);
      const std::int32_t* voters = neighborhoods.indices.data() + neighborhoods.begin(i);
      for (std::size_t j = 0; j < k; ++j) {
        const auto voter = static_cast<std::size_t>(voters[j]);
        batch.nx[j] = normals[3 * voter];
        batch.ny[j] = normals[3 * voter + 1];
        batch.nz[j] = normals[3 * voter + 2];
        batch.stick[j] = stick[voter];
        batch.ball[j] = ball[voter];
      }
      // The votee's own normal counts as a vote of weight 1 (decay at distance 0).
      Eigen::Matrix3d tensor = StickTensor(batch, k, params);
      const Eigen::Vector3d own(normals[3 * i], normals[3 * i + 1], normals[3 * i + 2]);
      tensor += static_cast<double>(stick[i]) * own * own.transpose();
      Store(Decompose(tensor), i, result);
    });
  }
}

}  // namespace

TensorVotingResult RunTensorVoting(const std::vector<Eigen::Vector3d>& points,
                                   const TensorVotingOptions& options) {
  options.Check();
  const std::size_t n = points.size();
  const std::vector<std::int32_t> order = MortonOrder(points, options.radius());
  // Breaks in the sorted sequence: ~n for a map in hash order, a few per point that a float
  // round trip moved across a cell border for a map written by `planeloc map build` (already
  // sorted), for which the input order is as local as the sorted copy.
  std::size_t breaks = 0;
  for (std::size_t k = 1; k < n; ++k) breaks += order[k] != order[k - 1] + 1;
  if (breaks <= n / 100) {
    TensorVotingResult result = EmptyResult(n);
    result.neighborhoods = FindNeighborhoods(points, options.radius(),
                                             static_cast<std::size_t>(options.max_neighbors));
    Vote(points, options, result.neighborhoods, result);
    return result;
  }
  std::vector<Eigen::Vector3d> sorted_points(n);
  ParallelFor(n, [&](std::size_t k) { sorted_points[k] = points[order[k]]; });
  TensorVotingResult sorted = EmptyResult(n);
  {
    const Neighborhoods sorted_hoods = FindNeighborhoods(
        sorted_points, options.radius(), static_cast<std::size_t>(options.max_neighbors));
    Vote(sorted_points, options, sorted_hoods, sorted);
  }
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
  // Searching again in the input order costs about what renumbering the sorted graph would, and
  // never holds two graphs in memory.
  result.neighborhoods =
      FindNeighborhoods(points, options.radius(), static_cast<std::size_t>(options.max_neighbors));
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
