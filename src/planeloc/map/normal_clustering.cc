#include "planeloc/map/normal_clustering.h"

#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

Eigen::Vector3d PrincipalAxis(const Eigen::Matrix3d& scatter) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  return solver.eigenvectors().col(2).normalized();
}

// Assigns every normal to its nearest axis and returns the per-centre scatter sums. The work is cut
// into a fixed number of blocks summed in block order, so the floating-point result does not depend
// on the thread schedule.
std::vector<Eigen::Matrix3d> Assign(const std::vector<Eigen::Vector3d>& normals,
                                    const std::vector<float>& weights,
                                    const std::vector<Eigen::Vector3d>& centers,
                                    std::vector<int>& labels) {
  constexpr std::size_t kBlocks = 64;
  const std::size_t n = normals.size();
  const std::size_t k = centers.size();
  std::vector<std::vector<Eigen::Matrix3d>> block_sums(
      kBlocks, std::vector<Eigen::Matrix3d>(k, Eigen::Matrix3d::Zero()));
  tbb::parallel_for(std::size_t{0}, kBlocks, [&](std::size_t block) {
    const std::size_t begin = n * block / kBlocks, end = n * (block + 1) / kBlocks;
    for (std::size_t i = begin; i < end; ++i) {
      int best = 0;
      double best_dot = -1.0;
      for (std::size_t c = 0; c < k; ++c) {
        const double dot = std::abs(normals[i].dot(centers[c]));
        if (dot > best_dot) {
          best_dot = dot;
          best = static_cast<int>(c);
        }
      }
      labels[i] = best;
      const double w = weights.empty() ? 1.0 : weights[i];
      block_sums[block][best].noalias() += w * (normals[i] * normals[i].transpose());
    }
  });
  std::vector<Eigen::Matrix3d> sums(k, Eigen::Matrix3d::Zero());
  for (const auto& block : block_sums) {
    for (std::size_t c = 0; c < k; ++c) sums[c] += block[c];
  }
  return sums;
}

std::vector<Eigen::Vector3d> Seed(const std::vector<Eigen::Vector3d>& normals,
                                  const NormalClusteringOptions& options) {
  const std::size_t stride =
      std::max<std::size_t>(1, normals.size() / static_cast<std::size_t>(options.max_seed_samples));
  std::vector<Eigen::Vector3d> samples;
  for (std::size_t i = 0; i < normals.size(); i += stride) samples.push_back(normals[i]);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& s : samples) scatter.noalias() += s * s.transpose();
  std::vector<Eigen::Vector3d> centers = {PrincipalAxis(scatter)};
  std::vector<double> nearest(samples.size(), 0.0);  // max |dot| to any centre
  const double merge_cos = std::cos(options.merge_angle_deg * std::numbers::pi / 180.0);
  while (static_cast<int>(centers.size()) < options.max_clusters) {
    std::size_t farthest = 0;
    for (std::size_t i = 0; i < samples.size(); ++i) {
      nearest[i] = std::max(nearest[i], std::abs(samples[i].dot(centers.back())));
      if (nearest[i] < nearest[farthest]) farthest = i;
    }
    if (nearest[farthest] >= merge_cos) break;  // every sample is near a centre already
    centers.push_back(samples[farthest]);
  }
  return centers;
}

}  // namespace

void NormalClusteringOptions::Check() const {
  if (max_clusters < 1 || max_clusters > 200) {
    throw OptionsError("NormalClusteringOptions.max_clusters must be in [1, 200]");
  }
  if (!(merge_angle_deg > 0.0 && merge_angle_deg < 90.0)) {
    throw OptionsError("NormalClusteringOptions.merge_angle_deg must be in (0, 90)");
  }
  if (iterations < 1) throw OptionsError("NormalClusteringOptions.iterations must be >= 1");
  if (max_seed_samples < 1) {
    throw OptionsError("NormalClusteringOptions.max_seed_samples must be >= 1");
  }
}

NormalClusters ClusterNormals(const std::vector<Eigen::Vector3d>& normals,
                              const std::vector<float>& weights,
                              const NormalClusteringOptions& options) {
  options.Check();
  NormalClusters result;
  if (normals.empty()) return result;
  const double merge_cos = std::cos(options.merge_angle_deg * std::numbers::pi / 180.0);
  std::vector<Eigen::Vector3d> centers = Seed(normals, options);
  std::vector<int> labels(normals.size(), 0);
  std::vector<Eigen::Matrix3d> sums;
  for (int round = 0; round < 50; ++round) {
    for (int it = 0; it < options.iterations; ++it) {
      sums = Assign(normals, weights, centers, labels);
      std::vector<Eigen::Vector3d> updated;
      for (std::size_t c = 0; c < centers.size(); ++c) {
        if (sums[c].trace() > 0.0) updated.push_back(PrincipalAxis(sums[c]));
      }
      const bool same =
          updated.size() == centers.size() &&
          std::equal(updated.begin(), updated.end(), centers.begin(),
                     [](const auto& a, const auto& b) { return std::abs(a.dot(b)) > 1.0 - 1e-12; });
      centers = std::move(updated);
      if (same) break;
    }
    sums = Assign(normals, weights, centers, labels);
    // Merge the closest pair of centres if it is within the merge angle, then iterate again.
    double best = merge_cos;
    std::size_t a = 0, b = 0;
    for (std::size_t i = 0; i < centers.size(); ++i) {
      for (std::size_t j = i + 1; j < centers.size(); ++j) {
        const double dot = std::abs(centers[i].dot(centers[j]));
        if (dot >= best) {
          best = dot;
          a = i;
          b = j;
        }
      }
    }
    if (a == b) break;
    centers[a] = PrincipalAxis(sums[a] + sums[b]);
    centers.erase(centers.begin() + static_cast<std::ptrdiff_t>(b));
  }
  // Order centres by weight so labels are stable and the dominant orientation comes first.
  std::vector<std::size_t> order(centers.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t x, std::size_t y) { return sums[x].trace() > sums[y].trace(); });
  std::vector<int> rank(centers.size());
  for (std::size_t r = 0; r < order.size(); ++r) {
    result.centers.push_back(centers[order[r]]);
    rank[order[r]] = static_cast<int>(r);
  }
  result.labels.resize(labels.size());
  for (std::size_t i = 0; i < labels.size(); ++i) result.labels[i] = rank[labels[i]];
  return result;
}

}  // namespace planeloc
