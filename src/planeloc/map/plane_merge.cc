#include "planeloc/map/plane_merge.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <set>
#include <stdexcept>
#include <unordered_map>

#include "planeloc/map/plane_extraction.h"
#include "planeloc/map/plane_outline.h"
#include "planeloc/map/plane_uncertainty.h"

namespace planeloc {
namespace {

struct PieceRef {
  int tile = 0;
  const TilePiece* piece = nullptr;
};

int Find(std::vector<int>& parent, int x) {
  while (parent[x] != x) x = parent[x] = parent[parent[x]];
  return x;
}

// Step 1: the up of the most core points among the tiles that detected one.
Eigen::Vector3d GlobalUp(const std::vector<TilePlanes>& tiles, const MapPlanesOptions& options,
                         bool& detected) {
  detected = false;
  if (!options.plane_extraction.detect_up) return options.plane_extraction.up.normalized();
  std::vector<std::pair<Eigen::Vector3d, std::size_t>> votes;
  for (const TilePlanes& t : tiles) {
    if (!t.up_detected) continue;
    auto it = std::find_if(votes.begin(), votes.end(),
                           [&](const auto& v) { return v.first.dot(t.up) > 0.999; });
    if (it == votes.end()) {
      votes.emplace_back(t.up, t.core_points);
    } else {
      it->second += t.core_points;
    }
  }
  if (votes.empty()) return options.plane_extraction.up.normalized();
  detected = true;
  return std::max_element(votes.begin(), votes.end(),  // first of equal maxima
                          [](const auto& a, const auto& b) { return a.second < b.second; })
      ->first;
}

// The untiled patch-merge test (plane_extraction.cc, step 5) on two pieces.
bool SamePlane(const TilePiece& a, const TilePiece& b, const PlaneExtractionOptions& options) {
  const Plane& pa = a.plane.plane_in_map;
  const Plane& pb = b.plane.plane_in_map;
  const double cos_merge = std::cos(options.merge_angle_deg * std::numbers::pi / 180.0);
  return std::abs(pa.normal.dot(pb.normal)) >= cos_merge &&
         std::abs(pa.SignedDistance(b.core_mean)) <= options.merge_distance &&
         std::abs(pb.SignedDistance(a.core_mean)) <= options.merge_distance;
}

struct CellHash {
  std::size_t operator()(const Eigen::Vector3i& c) const {
    return (static_cast<std::size_t>(c.x()) * 73856093u) ^
           (static_cast<std::size_t>(c.y()) * 19349663u) ^
           (static_cast<std::size_t>(c.z()) * 83492791u);
  }
};

// Step 2: union-find over the pieces. Only a plane a border cut is re-joined: a piece of tile T
// continues into the overlap band (its band samples), which is the core of a neighbour U, and
// U's piece there holds core samples in the same outline cells (the same points, seen by both
// tiles). Two pieces of one tile are never joined directly: the tile's own extraction, which saw
// their whole neighbourhood, kept them apart by the untiled rules. Candidate pairs are taken in
// (piece, piece) order, whatever the number of ranks.
std::vector<int> JoinAcrossBorders(const std::vector<PieceRef>& pieces,
                                   const PlaneExtractionOptions& options) {
  const double cell = options.outline.cell_size;
  auto key = [cell](const Eigen::Vector3d& s) {
    return Eigen::Vector3i((s / cell).array().floor().cast<int>());
  };
  std::unordered_map<Eigen::Vector3i, std::vector<int>, CellHash> core_cells;
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    for (const auto& s : pieces[k].piece->samples) core_cells[key(s)].push_back(k);
  }
  // (a, b): a's band samples fall in outline cells of b's core. A plane the border cuts is seen
  // across it by both tiles, so it reaches into the other's core both ways; a piece that reaches
  // one way only is a plane one tile's extraction grew across a gap near the border into a
  // neighbour that the other tile (and the untiled map) keeps apart (kitti07-like seed 1: a 37 m^2
  // sidewalk ending 0.3 m before a border, whole in its tile, was joined into the sidewalk beyond
  // a crossing).
  std::set<std::pair<int, int>> reaches;
  for (std::size_t a = 0; a < pieces.size(); ++a) {
    for (const auto& s : pieces[a].piece->band_samples) {
      const auto it = core_cells.find(key(s));
      if (it == core_cells.end()) continue;
      for (const int b : it->second) {
        if (pieces[b].tile != pieces[a].tile) reaches.emplace(static_cast<int>(a), b);
      }
    }
  }
  std::set<std::pair<int, int>> shared;  // (a < b) reaching into each other's cores
  for (const auto& [a, b] : reaches) {
    if (a < b && reaches.count({b, a})) shared.emplace(a, b);
  }
  // The joint fit of a group uses the pieces' core inliers (JointPlaneHoldsAll): a chain of
  // pieces that are pairwise within merge_distance (a road whose height changes along the drive)
  // is not one plane.
  std::vector<PlanarPartMoments> moments(pieces.size());
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const TilePiece& p = *pieces[k].piece;
    moments[k].count = static_cast<double>(p.core_inliers);
    moments[k].mean = p.core_mean;
    moments[k].scatter = p.core_scatter;
    moments[k].normal = p.plane.plane_in_map.normal;
    moments[k].Finish();
  }
  std::vector<int> parent(pieces.size());
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::vector<const PlanarPartMoments*>> members(pieces.size());  // per root
  for (std::size_t k = 0; k < pieces.size(); ++k) members[k] = {&moments[k]};
  for (const auto& [a, b] : shared) {
    const int ra = Find(parent, a), rb = Find(parent, b);
    if (ra == rb || !SamePlane(*pieces[a].piece, *pieces[b].piece, options)) continue;
    std::vector<const PlanarPartMoments*> both = members[ra];
    both.insert(both.end(), members[rb].begin(), members[rb].end());
    if (!JointPlaneHoldsAll(both, options)) continue;
    parent[ra] = rb;
    members[rb] = std::move(both);
    members[ra].clear();
  }
  return parent;
}

// Step 3 for a group of pieces: fit, outline, filters. Returns false when rejected.
bool DescribeGroup(const std::vector<const TilePiece*>& group,
                   const PlaneExtractionOptions& options, const Eigen::Vector3d& up,
                   MapPlane& out) {
  std::size_t count = 0;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const TilePiece* p : group) {
    count += p->core_inliers;
    mean += static_cast<double>(p->core_inliers) * p->core_mean;
  }
  mean /= static_cast<double>(count);
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const TilePiece* p : group) {  // parallel-axis theorem: scatter about the common mean
    const Eigen::Vector3d r = p->core_mean - mean;
    scatter += p->core_scatter + static_cast<double>(p->core_inliers) * r * r.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  const double rms = std::sqrt(std::max(0.0, solver.eigenvalues()(0)) / count);
  if (static_cast<int>(count) < options.min_inliers || rms > options.max_rms) return false;
  const Eigen::Vector3d normal = solver.eigenvectors().col(0).normalized();
  out.plane_in_map =
      OrientPlane(Plane::FromPointAndNormal(mean, normal), up, options.kind_angle_deg);
  const Eigen::Vector3d& n = out.plane_in_map.normal;
  const Eigen::Vector3d helper =
      std::abs(n.dot(up)) < 0.9 ? up : Eigen::Vector3d(Eigen::Vector3d::UnitX());
  const Eigen::Vector3d u = n.cross(helper).normalized();
  const Eigen::Vector3d v = n.cross(u);
  const Eigen::Vector3d centroid = out.plane_in_map.Project(mean);
  std::vector<Eigen::Vector2d> flat;
  Eigen::Matrix2d flat_scatter = Eigen::Matrix2d::Zero();
  for (const TilePiece* p : group) {
    for (const auto& s : p->samples) {
      flat.emplace_back((s - centroid).dot(u), (s - centroid).dot(v));
      flat_scatter.noalias() += flat.back() * flat.back().transpose();
    }
  }
  const Eigen::Vector2d minor =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d>(flat_scatter).eigenvectors().col(0);
  double lo = 0.0, hi = 0.0;
  for (const auto& f : flat) {
    lo = std::min(lo, f.dot(minor));
    hi = std::max(hi, f.dot(minor));
  }
  if (hi - lo < options.min_extent) return false;
  const PlaneOutline2d outline = ComputePlaneOutline2d(flat, options.outline);
  if (outline.area < options.min_area) return false;
  out.area = outline.area;
  out.polygon.clear();
  for (const auto& h : outline.ring) out.polygon.push_back(centroid + h.x() * u + h.y() * v);
  out.centroid = centroid;
  out.inliers = static_cast<int>(count);
  out.rms = rms;
  std::vector<Eigen::Vector3d> samples;
  for (const TilePiece* p : group)
    samples.insert(samples.end(), p->samples.begin(), p->samples.end());
  out.sigma = PlaneSigmaFromSpread(
      MeasureSampledPlaneSpread(samples, out.inliers, out.rms, out.plane_in_map));
  return true;
}

}  // namespace

MergedPlanes MergeTilePlanes(const std::vector<TilePlanes>& tiles,
                             const MapPlanesOptions& options) {
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    if (!tiles[t].error.empty()) throw std::invalid_argument("MergeTilePlanes: a tile failed");
    if (t > 0 && !(tiles[t - 1].key < tiles[t].key)) {
      throw std::invalid_argument("MergeTilePlanes: tiles not sorted by key");
    }
  }
  const PlaneExtractionOptions& pe = options.plane_extraction;
  MergedPlanes merged;
  merged.up = GlobalUp(tiles, options, merged.up_detected);
  std::vector<PieceRef> pieces;
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    for (const TilePiece& p : tiles[t].pieces) pieces.push_back({static_cast<int>(t), &p});
  }
  std::vector<int> parent = JoinAcrossBorders(pieces, pe);
  std::vector<std::vector<int>> groups(pieces.size());
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    groups[Find(parent, static_cast<int>(k))].push_back(static_cast<int>(k));
  }
  struct Candidate {
    MapPlane plane;
    std::vector<int> members;
  };
  std::vector<Candidate> planes;
  std::size_t groups_joined = 0;
  // In the order of their first piece (tile key, tile plane id), whatever the union order.
  std::erase_if(groups, [](const std::vector<int>& g) { return g.empty(); });
  std::sort(groups.begin(), groups.end(),
            [](const auto& a, const auto& b) { return a.front() < b.front(); });
  for (const auto& members : groups) {
    Candidate c;
    c.members = members;
    const TilePiece& first = *pieces[members.front()].piece;
    if (members.size() == 1 && first.complete) {
      c.plane = first.plane;
      c.plane.plane_in_map = OrientPlane(c.plane.plane_in_map, merged.up, pe.kind_angle_deg);
    } else {
      groups_joined += members.size() > 1;
      std::vector<const TilePiece*> group;
      for (const int k : members) group.push_back(pieces[k].piece);
      if (!DescribeGroup(group, pe, merged.up, c.plane)) continue;
    }
    c.plane.kind = PlaneKind(c.plane.plane_in_map.normal, merged.up, pe.kind_angle_deg);
    planes.push_back(std::move(c));
  }
  // Groups are in order of their first piece (tile key, tile plane id): a deterministic tie-break.
  std::stable_sort(planes.begin(), planes.end(), [](const Candidate& a, const Candidate& b) {
    return a.plane.inliers > b.plane.inliers;
  });
  std::size_t plane_points = 0;
  for (std::size_t id = 0; id < planes.size(); ++id) {
    planes[id].plane.id = static_cast<int>(id);
    for (const int k : planes[id].members) {
      merged.piece_ids[{pieces[k].tile, pieces[k].piece->plane.id}] = static_cast<int>(id);
      plane_points += pieces[k].piece->core_inliers;
    }
    merged.plane_map.planes.push_back(std::move(planes[id].plane));
  }
  std::size_t points = 0;
  for (const TilePlanes& t : tiles) points += t.core_points;
  nlohmann::json& stats = merged.plane_map.stats;
  stats["tiles"] = tiles.size();
  stats["points"] = points;
  stats["pieces"] = pieces.size();
  stats["joined_groups"] = groups_joined;
  stats["planes"] = merged.plane_map.planes.size();
  stats["plane_points"] = plane_points;
  stats["up"] = {merged.up.x(), merged.up.y(), merged.up.z()};
  stats["up_detected"] = merged.up_detected;
  return merged;
}

PlaneMapTally MergeTileTallies(const std::vector<TilePlanes>& tiles, const MergedPlanes& merged) {
  PlaneMapTally total;
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    if (!tiles[t].gt) continue;
    PlaneMapTally tally = *tiles[t].gt;
    for (auto& votes : tally.labels) {
      std::map<int, std::size_t> relabelled;
      for (const auto& [id, count] : votes) {
        const auto it = merged.piece_ids.find({static_cast<int>(t), id});
        if (it != merged.piece_ids.end()) relabelled[it->second] += count;
      }
      votes = std::move(relabelled);
    }
    total.Merge(tally);
  }
  return total;
}

}  // namespace planeloc
