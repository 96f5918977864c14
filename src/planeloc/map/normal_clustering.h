// Sign-invariant k-means on unit normals (axial / "projective-sphere" k-means): n and -n are the
// same orientation. A point belongs to the centre c maximizing |n . c|, and a centre is the
// principal eigenvector of its members' weighted sum of n n^T — the axial mean, which minimizes the
// sum of sin^2 of the angles. Seeding is deterministic (dominant axis, then farthest point) and k
// is chosen automatically: start with `max_clusters`, then repeatedly merge centres closer than
// `merge_angle_deg` and re-run Lloyd until nothing merges.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace planeloc {

struct NormalClusteringOptions {
  int max_clusters = 20;          // initial k (upper bound of the result)
  double merge_angle_deg = 12.0;  // centres closer than this are one orientation
  int iterations = 15;            // Lloyd iterations per round
  int max_seed_samples = 20000;   // seeding looks at most at this many (evenly spaced) normals
  void Check() const;             // throws OptionsError
};

struct NormalClusters {
  std::vector<Eigen::Vector3d> centers;  // unit axes, sorted by decreasing weight
  std::vector<int> labels;               // per input normal, index into centers
};

// `weights` (e.g. stick saliencies) may be empty for uniform weights. Deterministic for any number
// of threads.
NormalClusters ClusterNormals(const std::vector<Eigen::Vector3d>& normals,
                              const std::vector<float>& weights,
                              const NormalClusteringOptions& options);

}  // namespace planeloc
