#include "planeloc/map/plane_extraction.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <numbers>
#include <numeric>
#include <optional>
#include <random>

#include "planeloc/map/plane_uncertainty.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

double Cos(double degrees) { return std::cos(degrees * std::numbers::pi / 180.0); }

// Running sums for an incremental plane fit (centroid and scatter).
struct PlaneSums {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  std::size_t count = 0;

  void Add(const Eigen::Vector3d& p) {
    sum += p;
    outer.noalias() += p * p.transpose();
    ++count;
  }
  // Smallest-eigenvalue direction of the covariance, through the centroid.
  Plane Fit() const {
    const Eigen::Vector3d centroid = sum / static_cast<double>(count);
    const Eigen::Matrix3d covariance =
        outer / static_cast<double>(count) - centroid * centroid.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(covariance);
    return Plane::FromPointAndNormal(centroid, solver.eigenvectors().col(0));
  }
};

// A spatially connected coplanar patch: its points and plane.
struct Patch {
  std::vector<int> points;
  Plane plane;
  double rms = 0.0;
};

// Step 3: region growing of one patch from `seed` over same-cluster unassigned neighbours.
std::vector<int> GrowPatch(int seed, const std::vector<Eigen::Vector3d>& points,
                           const TensorVotingResult& voting, const std::vector<int>& cluster,
                           std::vector<int>& assigned, int patch_id,
                           const PlaneExtractionOptions& options) {
  const double cos_growth = Cos(options.growth_angle_deg);
  const Neighborhoods& hoods = voting.neighborhoods;
  PlaneSums sums;
  Plane plane = Plane::FromPointAndNormal(points[seed], voting.normals[seed]);
  std::vector<int> members = {seed};
  assigned[seed] = patch_id;
  sums.Add(points[seed]);
  std::size_t next_refit = 16;
  for (std::size_t head = 0; head < members.size(); ++head) {
    const int p = members[head];
    for (auto k = hoods.begin(p); k < hoods.end(p); ++k) {
      const int j = hoods.indices[k];
      if (assigned[j] >= 0 || cluster[j] != cluster[seed]) continue;
      if (std::abs(voting.normals[j].dot(plane.normal)) < cos_growth) continue;
      if (std::abs(plane.SignedDistance(points[j])) > options.growth_distance) continue;
      assigned[j] = patch_id;
      members.push_back(j);
      sums.Add(points[j]);
      if (sums.count >= next_refit) {
        plane = sums.Fit();
        next_refit *= 2;
      }
    }
  }
  return members;
}

// Steps 2-4: orientation clusters, then patches by region growing, then a robust fit each.
std::vector<Patch> FindPatches(const std::vector<Eigen::Vector3d>& points,
                               const TensorVotingResult& voting,
                               const PlaneExtractionOptions& options, nlohmann::json& stats) {
  std::vector<int> surface;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (voting.classes[i] == SaliencyClass::kSurface &&
        voting.stick[i] >= options.min_stick_saliency) {
      surface.push_back(static_cast<int>(i));
    }
  }
  stats["surface_points"] = surface.size();
  std::vector<Eigen::Vector3d> normals;
  std::vector<float> weights;
  for (const int i : surface) {
    normals.push_back(voting.normals[i]);
    weights.push_back(voting.stick[i]);
  }
  const NormalClusters clusters = ClusterNormals(normals, weights, options.clustering);
  stats["normal_clusters"] = clusters.centers.size();
  std::vector<int> cluster(points.size(), -1);
  for (std::size_t s = 0; s < surface.size(); ++s) cluster[surface[s]] = clusters.labels[s];
  // Seeds in order of decreasing saliency: the most planar points start patches.
  std::vector<int> seeds = surface;
  std::stable_sort(seeds.begin(), seeds.end(),
                   [&](int a, int b) { return voting.stick[a] > voting.stick[b]; });
  std::vector<int> assigned(points.size(), -1);
  std::vector<Patch> patches;
  for (const int seed : seeds) {
    if (assigned[seed] != -1) continue;
    const int id = static_cast<int>(patches.size());
    std::vector<int> members = GrowPatch(seed, points, voting, cluster, assigned, id, options);
    if (static_cast<int>(members.size()) < options.min_patch_points) {
      for (const int m : members) assigned[m] = -2;  // tried: neither seed nor member again
      continue;
    }
    Patch patch;
    std::vector<int> inliers;
    if (!FitPlaneRobust(points, members, options.inlier_distance, patch.plane, inliers,
                        patch.rms)) {
      continue;
    }
    // Members the fit left out go back to the pool: typically the far side of a small step (a
    // kerb) that the growth crossed, which belongs to the next patch.
    for (const int m : members) assigned[m] = -1;
    for (const int i : inliers) assigned[i] = id;
    patch.points = std::move(inliers);
    patches.push_back(std::move(patch));
  }
  stats["patches"] = patches.size();
  return patches;
}

int Find(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// Step 5: merges adjacent patches lying on the same plane, then refits the merged groups.
std::vector<Patch> MergePatches(const std::vector<Eigen::Vector3d>& points,
                                const Neighborhoods& hoods, std::vector<Patch> patches,
                                const PlaneExtractionOptions& options) {
  std::vector<int> owner(points.size(), -1);
  for (std::size_t p = 0; p < patches.size(); ++p) {
    for (const int i : patches[p].points) owner[i] = static_cast<int>(p);
  }
  std::vector<std::pair<int, int>> adjacent;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (owner[i] < 0) continue;
    for (auto k = hoods.begin(i); k < hoods.end(i); ++k) {
      const int o = owner[hoods.indices[k]];
      if (o > owner[i]) adjacent.emplace_back(owner[i], o);
    }
  }
  std::sort(adjacent.begin(), adjacent.end());
  adjacent.erase(std::unique(adjacent.begin(), adjacent.end()), adjacent.end());
  std::vector<int> parent(patches.size());
  std::iota(parent.begin(), parent.end(), 0);
  const double cos_merge = Cos(options.merge_angle_deg);
  std::vector<PlanarPartMoments> moments(patches.size());
  for (std::size_t p = 0; p < patches.size(); ++p) {
    PlanarPartMoments& m = moments[p];
    m.count = static_cast<double>(patches[p].points.size());
    for (const int i : patches[p].points) m.mean += points[i];
    m.mean /= m.count;
    for (const int i : patches[p].points) {
      const Eigen::Vector3d r = points[i] - m.mean;
      m.scatter.noalias() += r * r.transpose();
    }
    m.normal = patches[p].plane.normal;
    m.Finish();
  }
  // Members of each union-find root: a join must leave the group's joint plane holding every
  // member, so a chain of pairwise-coplanar patches across a kerb (road, a patch straddling the
  // kerb, sidewalk) does not become one group whose refit keeps the road and drops the sidewalk.
  std::vector<std::vector<const PlanarPartMoments*>> members(patches.size());
  for (std::size_t p = 0; p < patches.size(); ++p) members[p] = {&moments[p]};
  for (const auto& [a, b] : adjacent) {
    const int ra = Find(parent, a), rb = Find(parent, b);
    if (ra == rb) continue;
    const Plane& pa = patches[a].plane;
    const Plane& pb = patches[b].plane;
    if (std::abs(pa.normal.dot(pb.normal)) < cos_merge) continue;
    if (std::abs(pa.SignedDistance(moments[b].mean)) > options.merge_distance) continue;
    if (std::abs(pb.SignedDistance(moments[a].mean)) > options.merge_distance) continue;
    std::vector<const PlanarPartMoments*> both = members[ra];
    both.insert(both.end(), members[rb].begin(), members[rb].end());
    if (!JointPlaneHoldsAll(both, options)) continue;
    parent[ra] = rb;
    members[rb] = std::move(both);
    members[ra].clear();
  }
  std::vector<std::vector<int>> groups(patches.size());
  for (std::size_t p = 0; p < patches.size(); ++p) {
    auto& group = groups[Find(parent, static_cast<int>(p))];
    group.insert(group.end(), patches[p].points.begin(), patches[p].points.end());
  }
  std::vector<Patch> merged;
  for (auto& group : groups) {
    if (group.empty()) continue;
    std::sort(group.begin(), group.end());
    Patch patch;
    std::vector<int> inliers;
    if (!FitPlaneRobust(points, group, options.inlier_distance, patch.plane, inliers, patch.rms)) {
      continue;
    }
    patch.points = std::move(inliers);
    merged.push_back(std::move(patch));
  }
  return merged;
}

// Orientation convention: ground normals point up; other normals have a positive largest
// component, so the same plane always gets the same (n, d).
Plane Orient(const Plane& plane, const Eigen::Vector3d& up, double cos_kind) {
  const Eigen::Vector3d& n = plane.normal;
  if (std::abs(n.dot(up)) >= cos_kind) return n.dot(up) >= 0.0 ? plane : plane.Flipped();
  Eigen::Index axis = 0;
  n.cwiseAbs().maxCoeff(&axis);
  return n(axis) >= 0.0 ? plane : plane.Flipped();
}

// Steps 6-7 for one patch: outline, area, extent, kind. Returns false when rejected.
bool Describe(const std::vector<Eigen::Vector3d>& points, const Patch& patch,
              const PlaneExtractionOptions& options, MapPlane& out) {
  if (static_cast<int>(patch.points.size()) < options.min_inliers) return false;
  if (patch.rms > options.max_rms) return false;
  const Eigen::Vector3d up = options.up.normalized();
  const double cos_kind = Cos(options.kind_angle_deg);
  out.plane_in_map = Orient(patch.plane, up, cos_kind);
  const Eigen::Vector3d& n = out.plane_in_map.normal;
  const Eigen::Vector3d helper =
      std::abs(n.dot(up)) < 0.9 ? up : Eigen::Vector3d(Eigen::Vector3d::UnitX());
  const Eigen::Vector3d u = n.cross(helper).normalized();
  const Eigen::Vector3d v = n.cross(u);
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const int i : patch.points) centroid += points[i];
  centroid /= static_cast<double>(patch.points.size());
  centroid = out.plane_in_map.Project(centroid);
  std::vector<Eigen::Vector2d> flat;
  flat.reserve(patch.points.size());
  Eigen::Matrix2d scatter = Eigen::Matrix2d::Zero();
  for (const int i : patch.points) {
    const Eigen::Vector3d r = points[i] - centroid;
    flat.emplace_back(r.dot(u), r.dot(v));
    scatter.noalias() += flat.back() * flat.back().transpose();
  }
  // Width along the minor principal axis of the inliers (the oriented box's short side).
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(scatter);
  const Eigen::Vector2d minor = solver.eigenvectors().col(0);
  double lo = 0.0, hi = 0.0;
  for (const auto& f : flat) {
    lo = std::min(lo, f.dot(minor));
    hi = std::max(hi, f.dot(minor));
  }
  if (hi - lo < options.min_extent) return false;
  const PlaneOutline2d outline = ComputePlaneOutline2d(flat, options.outline);
  out.area = outline.area;
  if (out.area < options.min_area) return false;
  out.polygon.clear();
  for (const auto& h : outline.ring) out.polygon.push_back(centroid + h.x() * u + h.y() * v);
  out.centroid = centroid;
  out.inliers = static_cast<int>(patch.points.size());
  out.rms = patch.rms;
  out.kind = PlaneKind(n, up, options.kind_angle_deg);
  const PlaneSpread spread = MeasurePlaneSpread(points, patch.points, out.plane_in_map);
  out.sigma = PlaneSigmaFromSpread(spread);
  return true;
}

// The up direction (see the header): dominant near-axis plane, signed by its off-plane neighbours.
// Returns false when no patch qualifies.
bool DetectUp(const std::vector<Eigen::Vector3d>& points, const Neighborhoods& hoods,
              const std::vector<Patch>& patches_by_size, const PlaneExtractionOptions& options,
              Eigen::Vector3d& up) {
  const Patch* dominant = nullptr;
  const Patch* largest = nullptr;
  Eigen::Vector3d axis = Eigen::Vector3d::Zero();
  const double cos_axis = Cos(2.0 * options.kind_angle_deg);
  for (const Patch& patch : patches_by_size) {
    if (static_cast<int>(patch.points.size()) < options.min_inliers) break;  // sorted by size
    if (patch.rms > options.max_rms) continue;
    if (!largest) largest = &patch;
    Eigen::Index k = 0;
    if (patch.plane.normal.cwiseAbs().maxCoeff(&k) >= cos_axis) {
      dominant = &patch;
      axis = Eigen::Vector3d::Unit(k);
      break;
    }
  }
  if (!dominant) {
    if (!largest) return false;
    dominant = largest;
    axis = largest->plane.normal;
  }
  const Plane& plane = dominant->plane;
  // Neighbours well off the plane (3 inlier distances: 24 cm) on each side. Kerbs, walls, cars
  // and trees stand on the ground; nothing lies under it. Closer to the plane, a real road that is
  // not flat over a scan (crown, slope: rms 3 cm on KITTI-00) puts thousands of its own points on
  // both sides: with the former 8 cm margin scan 000095 counted 7 758 above and 11 159 below and
  // chose down; at 24 cm the four KITTI-00 scans count 1 357-14 893 above and none below.
  const double margin = 3.0 * options.inlier_distance;
  const double side = plane.normal.dot(axis) >= 0.0 ? 1.0 : -1.0;  // +1: the normal is +axis
  std::size_t above = 0, below = 0;                                // along +axis
  const std::size_t stride = std::max<std::size_t>(1, dominant->points.size() / 20000);
  for (std::size_t s = 0; s < dominant->points.size(); s += stride) {
    const int i = dominant->points[s];
    for (auto k = hoods.begin(i); k < hoods.end(i); ++k) {
      const double height = side * plane.SignedDistance(points[hoods.indices[k]]);
      above += height > margin;
      below += height < -margin;
    }
  }
  up = above >= below ? axis : Eigen::Vector3d(-axis);
  up += Eigen::Vector3d::Zero();  // -0 + 0 = +0: no "-0" components in logs and planes.json
  return true;
}

}  // namespace

std::string PlaneKind(const Eigen::Vector3d& normal, const Eigen::Vector3d& up,
                      double kind_angle_deg) {
  const double up_dot = std::abs(normal.dot(up.normalized()));
  if (up_dot >= Cos(kind_angle_deg)) return "ground";
  // Within kind_angle_deg of horizontal: at least 90 - kind_angle_deg from up.
  if (up_dot <= std::sin(kind_angle_deg * std::numbers::pi / 180.0)) return "facade";
  return "other";
}

void PlaneExtractionOptions::Check() const {
  clustering.Check();
  outline.Check();
  auto require = [](bool ok, const char* message) {
    if (!ok) throw OptionsError(std::string("PlaneExtractionOptions.") + message);
  };
  require(min_stick_saliency >= 0.0 && min_stick_saliency <= 1.0,
          "min_stick_saliency must be in [0, 1]");
  require(growth_angle_deg > 0.0 && growth_angle_deg < 90.0, "growth_angle_deg must be in (0, 90)");
  require(growth_distance > 0.0, "growth_distance must be > 0 (metres)");
  require(min_patch_points >= 3, "min_patch_points must be >= 3");
  require(inlier_distance > 0.0, "inlier_distance must be > 0 (metres)");
  require(merge_angle_deg > 0.0 && merge_angle_deg < 90.0, "merge_angle_deg must be in (0, 90)");
  require(merge_distance >= 0.0, "merge_distance must be >= 0 (metres)");
  require(min_inliers >= 3, "min_inliers must be >= 3");
  require(min_area >= 0.0, "min_area must be >= 0 (m^2)");
  require(min_extent >= 0.0, "min_extent must be >= 0 (metres)");
  require(max_rms > 0.0, "max_rms must be > 0 (metres)");
  require(up.allFinite() && up.norm() > 1e-9, "up must be a non-zero vector");
  require(kind_angle_deg > 0.0 && kind_angle_deg < 45.0, "kind_angle_deg must be in (0, 45)");
}

namespace {

// The plane through three points of `sample` with the least sum of squared distances truncated at
// `band` over the sample (MSAC; deterministic: a fixed-seed generator, so the same patch always
// gives the same plane).
std::optional<Plane> ConsensusPlane(const std::vector<Eigen::Vector3d>& points,
                                    const std::vector<int>& sample, double band) {
  constexpr int kTrials = 128;
  std::mt19937 rng(static_cast<std::uint32_t>(sample.size()));
  std::uniform_int_distribution<std::size_t> pick(0, sample.size() - 1);
  std::optional<Plane> best;
  double best_cost = std::numeric_limits<double>::infinity();
  const double band2 = band * band;
  for (int trial = 0; trial < kTrials; ++trial) {
    const Eigen::Vector3d& a = points[sample[pick(rng)]];
    const Eigen::Vector3d& b = points[sample[pick(rng)]];
    const Eigen::Vector3d& c = points[sample[pick(rng)]];
    const Eigen::Vector3d normal = (b - a).cross(c - a);
    if (normal.norm() < 1e-6) continue;  // (nearly) collinear triple
    const Plane plane = Plane::FromPointAndNormal(a, normal.normalized());
    // MSAC (truncated squares), not the inlier count: a road beside a kerb-high sidewalk as wide
    // as half the road has more points within the band of a plane tilted by 1 deg across both
    // than of the road itself, but their distances to it are larger.
    double cost = 0.0;
    for (const int i : sample)
      cost += std::min(std::pow(plane.SignedDistance(points[i]), 2), band2);
    if (cost < best_cost) {
      best_cost = cost;
      best = plane;
    }
  }
  return best;
}

}  // namespace

void PlanarPartMoments::Finish() {
  own_residual = count > 0 ? std::max(0.0, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(
                                               scatter, Eigen::EigenvaluesOnly)
                                               .eigenvalues()(0))
                           : 0.0;
}

bool JointPlaneHoldsAll(const std::vector<const PlanarPartMoments*>& parts,
                        const PlaneExtractionOptions& options) {
  double count = 0.0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const PlanarPartMoments* part : parts) {
    count += part->count;
    mean += part->count * part->mean;
  }
  if (count <= 0.0) return false;
  mean /= count;
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const PlanarPartMoments* part : parts) {  // parallel-axis theorem
    const Eigen::Vector3d r = part->mean - mean;
    scatter += part->scatter + part->count * r * r.transpose();
  }
  const Eigen::Vector3d normal =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(scatter).eigenvectors().col(0).normalized();
  const double cos_merge = Cos(options.merge_angle_deg);
  const double allowed = 0.25 * options.inlier_distance;
  for (const PlanarPartMoments* part : parts) {
    if (part->count <= 0.0) continue;
    if (std::abs(normal.dot(part->normal)) < cos_merge) return false;
    const double offset = normal.dot(part->mean - mean);
    const double joint = (normal.dot(part->scatter * normal) + part->count * offset * offset);
    if (joint - part->own_residual > allowed * allowed * part->count) return false;
  }
  return true;
}

bool FitPlaneRobust(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& indices,
                    double inlier_distance, Plane& plane, std::vector<int>& inliers, double& rms) {
  if (indices.size() < 3) return false;
  // Start from the consensus plane of a sample, not from a least-squares fit of all points: a
  // patch that grew over a small step (road and the kerb-high sidewalk, 12 cm apart) has a
  // least-squares plane between the two layers that keeps both within the threshold, a fixed point
  // of plain trimming. The consensus plane sits on the dominant layer.
  std::vector<int> sample;
  const std::size_t stride = std::max<std::size_t>(1, indices.size() / 2000);
  for (std::size_t k = 0; k < indices.size(); k += stride) sample.push_back(indices[k]);
  const std::optional<Plane> start = ConsensusPlane(points, sample, 0.5 * inlier_distance);
  if (!start) return false;
  plane = *start;
  // The refits take the points within half the threshold, as the consensus did. Refitted on
  // everything within the full threshold, two layers more than the threshold but less than twice
  // it apart (road and sidewalk, 11 cm; threshold 8 cm) have a fixed point between them that
  // keeps both: a tile whose sidewalk was a third of its road's points settled there, 3.7 cm
  // above the road (issue 15, kitti07-like seed 2). A symmetric band around the surface does not
  // bias the fit of a single noisy layer.
  const double refit_band = 0.5 * inlier_distance;
  for (int round = 0; round < 4; ++round) {
    PlaneSums sums;
    for (const int i : indices) {
      if (std::abs(plane.SignedDistance(points[i])) <= refit_band) sums.Add(points[i]);
    }
    if (sums.count < 3) return false;
    plane = sums.Fit();
  }
  inliers.clear();
  for (const int i : indices) {
    if (std::abs(plane.SignedDistance(points[i])) <= inlier_distance) inliers.push_back(i);
  }
  if (inliers.size() < 3) return false;
  double sum2 = 0.0;
  for (const int i : inliers) sum2 += std::pow(plane.SignedDistance(points[i]), 2);
  rms = std::sqrt(sum2 / static_cast<double>(inliers.size()));
  return true;
}

std::vector<Eigen::Vector2d> ConvexHull2d(std::vector<Eigen::Vector2d> points) {
  std::sort(points.begin(), points.end(), [](const auto& a, const auto& b) {
    return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y());
  });
  if (points.size() < 3) return points;
  auto cross = [](const Eigen::Vector2d& o, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    return (a.x() - o.x()) * (b.y() - o.y()) - (a.y() - o.y()) * (b.x() - o.x());
  };
  std::vector<Eigen::Vector2d> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {  // lower chain
    while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0) --k;
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i > 0; --i) {  // upper chain
    while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i - 1]) <= 0) --k;
    hull[k++] = points[i - 1];
  }
  hull.resize(k - 1);
  return hull;
}

double PolygonArea2d(const std::vector<Eigen::Vector2d>& polygon) {
  double twice = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const auto& a = polygon[i];
    const auto& b = polygon[(i + 1) % polygon.size()];
    twice += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * std::abs(twice);
}

Plane OrientPlane(const Plane& plane, const Eigen::Vector3d& up, double kind_angle_deg) {
  return Orient(plane, up.normalized(), Cos(kind_angle_deg));
}

PlaneExtractionResult ExtractPlanes(const std::vector<Eigen::Vector3d>& points,
                                    const TensorVotingResult& voting,
                                    const PlaneExtractionOptions& options) {
  options.Check();
  if (voting.size() != points.size() || voting.neighborhoods.size() != points.size()) {
    throw std::invalid_argument("ExtractPlanes: tensor-voting result does not match the points");
  }
  PlaneExtractionResult result;
  nlohmann::json& stats = result.plane_map.stats;
  stats["points"] = points.size();
  std::vector<Patch> patches = FindPatches(points, voting, options, stats);
  patches = MergePatches(points, voting.neighborhoods, std::move(patches), options);
  stats["merged_patches"] = patches.size();
  std::stable_sort(patches.begin(), patches.end(), [](const Patch& a, const Patch& b) {
    return a.points.size() > b.points.size();
  });
  PlaneExtractionOptions effective = options;
  result.up = options.up.normalized();
  if (options.detect_up && DetectUp(points, voting.neighborhoods, patches, options, effective.up)) {
    result.up = effective.up;
    result.up_detected = true;
  }
  stats["up"] = {result.up.x(), result.up.y(), result.up.z()};
  stats["up_detected"] = result.up_detected;
  result.point_plane.assign(points.size(), -1);
  std::size_t labelled = 0;
  for (const Patch& patch : patches) {
    MapPlane plane;
    if (!Describe(points, patch, effective, plane)) continue;
    plane.id = static_cast<int>(result.plane_map.planes.size());
    for (const int i : patch.points) result.point_plane[i] = plane.id;
    labelled += patch.points.size();
    result.plane_map.planes.push_back(std::move(plane));
  }
  stats["planes"] = result.plane_map.planes.size();
  stats["plane_points"] = labelled;
  return result;
}

}  // namespace planeloc
