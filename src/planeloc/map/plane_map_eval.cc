#include "planeloc/map/plane_map_eval.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <stdexcept>
#include <tuple>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// A GT plane's polygon in its own 2-D basis, for point-in-polygon tests.
struct FlatPolygon {
  Eigen::Vector3d u, v;
  std::vector<Eigen::Vector2d> ring;

  explicit FlatPolygon(const MapPlane& plane) {
    std::tie(u, v) = plane.plane_in_map.InPlaneBasis();
    for (const auto& p : plane.polygon) ring.emplace_back(p.dot(u), p.dot(v));
  }

  // A plane without an outline is unbounded.
  bool Contains(const Eigen::Vector3d& p) const {
    return ring.size() < 3 || InsidePolygon2d(ring, Eigen::Vector2d(p.dot(u), p.dot(v)));
  }
};

std::vector<const MapPlane*> Candidates(const PlaneMap& gt, const PlaneMapEvalOptions& options) {
  std::vector<const MapPlane*> candidates;
  for (const MapPlane& g : gt.planes) {
    if (std::find(options.kinds.begin(), options.kinds.end(), g.kind) != options.kinds.end()) {
      candidates.push_back(&g);
    }
  }
  return candidates;
}

}  // namespace

void PlaneMapEvalOptions::Check() const {
  if (!(point_area > 0.0)) throw OptionsError("PlaneMapEvalOptions.point_area must be > 0 (m^2)");
  if (!(min_visible_area >= 0.0)) {
    throw OptionsError("PlaneMapEvalOptions.min_visible_area must be >= 0 (m^2)");
  }
  if (!(on_plane_distance > 0.0)) {
    throw OptionsError("PlaneMapEvalOptions.on_plane_distance must be > 0 (m)");
  }
  if (!(max_angle_deg > 0.0)) throw OptionsError("PlaneMapEvalOptions.max_angle_deg must be > 0");
  if (!(max_offset > 0.0)) throw OptionsError("PlaneMapEvalOptions.max_offset must be > 0 (m)");
  if (!(labelled_distance > 0.0)) {
    throw OptionsError("PlaneMapEvalOptions.labelled_distance must be > 0 (m)");
  }
}

void PlaneMapTally::Merge(const PlaneMapTally& other) {
  if (visible.empty()) visible.assign(other.visible.size(), 0);
  if (labels.empty()) labels.resize(other.labels.size());
  if (other.visible.size() != visible.size()) {
    throw std::invalid_argument("PlaneMapTally::Merge: tallies of different GT plane sets");
  }
  for (std::size_t g = 0; g < visible.size(); ++g) {
    visible[g] += other.visible[g];
    for (const auto& [id, count] : other.labels[g]) labels[g][id] += count;
  }
  labelled += other.labelled;
  labelled_near += other.labelled_near;
}

nlohmann::json PlaneMapTally::ToJson() const {
  nlohmann::json votes = nlohmann::json::array();
  for (const auto& per_gt : labels) {
    nlohmann::json pairs = nlohmann::json::array();
    for (const auto& [id, count] : per_gt) pairs.push_back({id, count});
    votes.push_back(pairs);
  }
  return {{"visible", visible},
          {"labels", votes},
          {"labelled", labelled},
          {"labelled_near", labelled_near}};
}

PlaneMapTally PlaneMapTally::FromJson(const nlohmann::json& json) {
  PlaneMapTally tally;
  tally.visible = json.at("visible").get<std::vector<std::size_t>>();
  for (const auto& pairs : json.at("labels")) {
    auto& per_gt = tally.labels.emplace_back();
    for (const auto& pair : pairs) per_gt[pair.at(0).get<int>()] = pair.at(1).get<std::size_t>();
  }
  tally.labelled = json.at("labelled").get<std::size_t>();
  tally.labelled_near = json.at("labelled_near").get<std::size_t>();
  return tally;
}

nlohmann::json PlaneMapEvaluation::ToJson() const {
  nlohmann::json planes = nlohmann::json::array();
  for (const GtPlaneMatch& m : checked) {
    planes.push_back({{"gt_id", m.gt_id},
                      {"kind", m.kind},
                      {"visible_area", m.visible_area},
                      {"extracted_id", m.extracted_id},
                      {"support", m.support},
                      {"angle_deg", m.angle_deg},
                      {"offset", m.offset},
                      {"good", m.good}});
  }
  return {{"checked", checked.size()},
          {"good", good},
          {"labelled_points", labelled_points},
          {"labelled_on_gt", labelled_on_gt},
          {"planes", planes}};
}

PlaneMapTally TallyPlaneMap(const std::vector<Eigen::Vector3d>& map_points,
                            const std::vector<int>& point_plane, const PlaneMap& gt,
                            const PlaneMapEvalOptions& options) {
  options.Check();
  if (point_plane.size() != map_points.size()) {
    throw std::invalid_argument("EvaluatePlaneMap: one plane label per map point expected");
  }
  const std::vector<const MapPlane*> candidates = Candidates(gt, options);
  std::vector<FlatPolygon> outlines;
  for (const MapPlane* g : candidates) outlines.emplace_back(*g);
  PlaneMapTally empty;
  empty.visible.assign(candidates.size(), 0);
  empty.labels.resize(candidates.size());
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, map_points.size(), 4096), empty,
      [&](const tbb::blocked_range<std::size_t>& range, PlaneMapTally local) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const Eigen::Vector3d& p = map_points[i];
          for (std::size_t g = 0; g < candidates.size(); ++g) {
            if (std::abs(candidates[g]->plane_in_map.SignedDistance(p)) <
                    options.on_plane_distance &&
                outlines[g].Contains(p)) {
              ++local.visible[g];
              if (point_plane[i] >= 0) ++local.labels[g][point_plane[i]];
            }
          }
          if (point_plane[i] < 0) continue;
          ++local.labelled;
          for (const MapPlane& g : gt.planes) {
            if (std::abs(g.plane_in_map.SignedDistance(p)) < options.labelled_distance) {
              ++local.labelled_near;
              break;
            }
          }
        }
        return local;
      },
      [](PlaneMapTally a, const PlaneMapTally& b) {
        a.Merge(b);
        return a;
      });
}

PlaneMapEvaluation FinishPlaneMapEvaluation(const PlaneMapTally& tally, const PlaneMap& extracted,
                                            const PlaneMap& gt,
                                            const PlaneMapEvalOptions& options) {
  const std::vector<const MapPlane*> candidates = Candidates(gt, options);
  if (tally.visible.size() != candidates.size()) {
    throw std::invalid_argument("FinishPlaneMapEvaluation: the tally is of another GT");
  }
  std::map<int, const MapPlane*> by_id;
  for (const MapPlane& p : extracted.planes) by_id[p.id] = &p;
  PlaneMapEvaluation evaluation;
  for (std::size_t g = 0; g < candidates.size(); ++g) {
    const double area = static_cast<double>(tally.visible[g]) * options.point_area;
    if (area < options.min_visible_area) continue;
    GtPlaneMatch match;
    match.gt_id = candidates[g]->id;
    match.kind = candidates[g]->kind;
    match.visible_area = area;
    std::size_t best = 0;
    for (const auto& [id, count] : tally.labels[g]) {  // ascending ids: ties go to the lower id
      if (count > best && by_id.count(id)) {
        best = count;
        match.extracted_id = id;
      }
    }
    if (match.extracted_id >= 0) {
      const MapPlane& e = *by_id.at(match.extracted_id);
      match.support = static_cast<double>(best) / static_cast<double>(tally.visible[g]);
      match.angle_deg =
          e.plane_in_map.AngleTo(candidates[g]->plane_in_map) * 180.0 / std::numbers::pi;
      match.offset = std::abs(candidates[g]->plane_in_map.SignedDistance(e.centroid));
      match.good = match.angle_deg < options.max_angle_deg && match.offset < options.max_offset;
    }
    evaluation.good += match.good;
    evaluation.checked.push_back(match);
  }
  evaluation.labelled_points = tally.labelled;
  evaluation.labelled_on_gt = tally.labelled == 0 ? 0.0
                                                  : static_cast<double>(tally.labelled_near) /
                                                        static_cast<double>(tally.labelled);
  return evaluation;
}

PlaneMapEvaluation EvaluatePlaneMap(const std::vector<Eigen::Vector3d>& map_points,
                                    const std::vector<int>& point_plane, const PlaneMap& extracted,
                                    const PlaneMap& gt, const PlaneMapEvalOptions& options) {
  return FinishPlaneMapEvaluation(TallyPlaneMap(map_points, point_plane, gt, options), extracted,
                                  gt, options);
}

}  // namespace planeloc
