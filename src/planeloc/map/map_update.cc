#include "planeloc/map/map_update.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <utility>
#include <vector>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr double kRadiansPerDegree = std::numbers::pi / 180.0;
// A run's tilt sigma at or above this (radians) says it did not constrain that tilt
// (PlaneEvidence reports 1 rad then).
constexpr double kUnconstrainedTilt = 0.5;

using Vector3 = Eigen::Vector3d;

// The 99 % quantile of chi-square with `dof` degrees of freedom (0 for none); Wilson-Hilferty
// beyond the table.
double ChiSquare99(int dof) {
  static const double kTable[] = {0.0, 6.635, 9.210, 11.345, 13.277, 15.086};
  if (dof < 6) return kTable[std::max(0, dof)];
  const double k = dof, z = 2.326;
  return k * std::pow(1.0 - 2.0 / (9.0 * k) + z * std::sqrt(2.0 / (9.0 * k)), 3);
}

Vector3 Correction(const PlaneUpdate& update) {
  return Vector3(update.offset, update.tilt.x(), update.tilt.y());
}
Vector3 Variance(const PlaneUpdate& update) {
  return Vector3(update.offset_sigma, update.tilt_sigma.x(), update.tilt_sigma.y()).cwiseAbs2();
}

// The plane corrected by x = (offset at the centroid, tilt about e1, tilt about e2).
MapPlane Corrected(const MapPlane& plane, const Vector3& x) {
  MapPlane moved = plane;
  const Vector3& n = plane.plane_in_map.normal;
  const Vector3& e1 = plane.sigma.major_axis;
  const Vector3 normal = TiltedNormal(n, e1, x.tail<2>());
  const Vector3 centroid = plane.centroid + x[0] * n;
  moved.plane_in_map.normal = normal;
  moved.plane_in_map.d = -normal.dot(centroid);
  moved.centroid = centroid;
  for (Vector3& vertex : moved.polygon) {
    vertex -= moved.plane_in_map.SignedDistance(vertex) * normal;
  }
  // Keep the major axis in the new plane.
  moved.sigma.major_axis = (e1 - e1.dot(normal) * normal).normalized();
  return moved;
}

}  // namespace

const char* ToString(PlaneChangeAction action) {
  switch (action) {
    case PlaneChangeAction::kUnchanged:
      return "unchanged";
    case PlaneChangeAction::kConfirmed:
      return "confirmed";
    case PlaneChangeAction::kSuspect:
      return "suspect";
    case PlaneChangeAction::kMoved:
      return "moved";
    case PlaneChangeAction::kRetired:
      return "retired";
  }
  return "unchanged";
}

void CheckUpdatesMatch(const PlaneMap& map, const std::string& planes_hash,
                       const MapUpdates& updates) {
  const std::string updates_name = updates.source.string();
  const std::string map_name = map.source.string();
  const std::string fix =
      fmt::format("pass the planes.json the run used ({}), or run again on {} with --map-update",
                  updates.planes_path.string(), map_name);
  CheckInput(updates.planes_hash == planes_hash, updates_name, 0,
             fmt::format("was written by a run on another plane map: its planes.json hash is {}, "
                         "{} hashes to {}",
                         updates.planes_hash, map_name, planes_hash),
             fix);
  CheckInput(updates.planes_count == static_cast<int>(map.planes.size()), updates_name, 0,
             fmt::format("reports on {} planes, {} has {}", updates.planes_count, map_name,
                         map.planes.size()),
             fix);
  const std::string frame = map.frame.known() ? map.frame.name : "";
  CheckInput(updates.frame_name == frame, updates_name, 0,
             fmt::format("is in frame '{}', {} in frame '{}'", updates.frame_name, map_name, frame),
             fix);
  std::set<int> ids;
  for (const MapPlane& plane : map.planes) ids.insert(plane.id);
  for (const PlaneUpdate& update : updates.planes) {
    CheckInput(ids.count(update.id) > 0, updates_name, 0,
               fmt::format("reports on plane id {}, which {} does not have", update.id, map_name),
               fix);
  }
}

MapUpdateResult FuseMapUpdates(const PlaneMap& map, const std::vector<MapUpdates>& updates,
                               const MapUpdateOptions& options) {
  MapUpdateResult result;
  result.planes.stats = map.stats;
  result.planes.frame = map.frame;
  std::vector<std::map<int, const PlaneUpdate*>> by_id(updates.size());
  for (std::size_t k = 0; k < updates.size(); ++k) {
    for (const PlaneUpdate& update : updates[k].planes) by_id[k][update.id] = &update;
  }
  nlohmann::json retired = nlohmann::json::array();
  std::map<std::string, int> counts;
  for (const MapPlane& plane : map.planes) {
    PlaneChange change;
    change.id = plane.id;
    Vector3 information = Vector3::Zero();           // diagonal, sum of R_i^-1
    Vector3 weighted = Vector3::Zero();              // sum of R_i^-1 x_i
    std::vector<std::pair<double, double>> offsets;  // each measuring run's offset and variance
    std::set<std::string> sequences;                 // of the measuring runs
    MapPlane updated = plane;
    for (std::size_t k = 0; k < updates.size(); ++k) {
      const auto found = by_id[k].find(plane.id);
      if (found == by_id[k].end()) continue;
      const PlaneUpdate& update = *found->second;
      if (!update.frames.empty()) ++change.runs_seen;
      if (update.status == PlaneUpdateStatus::kContradicted) ++change.runs_contradicted;
      if (update.measured()) {
        ++change.runs_measured;
        const Vector3 inverse = Variance(update).cwiseInverse();
        information += inverse;
        weighted += inverse.cwiseProduct(Correction(update));
        offsets.emplace_back(update.offset, Variance(update)[0]);
        sequences.insert(updates[k].sequence);
      }
      if (update.status == PlaneUpdateStatus::kUnseen && update.frames.empty()) continue;
      nlohmann::json entry = {{"update", updates[k].source.filename().string()},
                              {"sequence", updates[k].sequence},
                              {"status", ToString(update.status)},
                              {"points", update.points},
                              {"through", update.through}};
      if (update.measured()) {
        entry["offset"] = update.offset;
        entry["offset_sigma"] = update.offset_sigma;
      }
      updated.provenance.push_back(std::move(entry));
    }
    const Vector3 prior(plane.sigma.offset, plane.sigma.normal.x(), plane.sigma.normal.y());
    const Vector3 prior_variance = prior.cwiseAbs2();
    if (change.runs_contradicted > 0 && change.runs_contradicted > change.runs_measured) {
      change.action = PlaneChangeAction::kRetired;
      change.reason = fmt::format(
          "{} of {} runs saw through it (points behind it on rays crossing its outline), {} "
          "measured it",
          change.runs_contradicted, change.runs_seen, change.runs_measured);
    } else if (change.runs_measured > 0) {
      const Vector3 runs_variance = information.cwiseInverse();
      const Vector3 runs = runs_variance.cwiseProduct(weighted);
      // A tilt no run constrained is not evidence either way.
      Vector3 tested = runs;
      for (int i = 1; i < 3; ++i) {
        if (runs_variance[i] >= kUnconstrainedTilt * kUnconstrainedTilt) tested[i] = 0;
      }
      change.chi2 = tested.cwiseAbs2().cwiseQuotient(prior_variance + runs_variance).sum();
      const bool large = std::abs(tested[0]) >= options.min_offset ||
                         tested.tail<2>().norm() >= options.min_tilt_deg * kRadiansPerDegree;
      // The runs must agree with each other before their mean replaces the plane: a run whose
      // trajectory was off measures every plane off by it.
      double spread = 0;
      for (const auto& [offset, variance] : offsets) {
        spread += (offset - runs[0]) * (offset - runs[0]) / variance;
      }
      const bool agree = spread <= ChiSquare99(static_cast<int>(offsets.size()) - 1);
      if (change.chi2 > options.chi2 && large &&
          static_cast<int>(sequences.size()) >= options.min_runs_to_move && agree) {
        change.action = PlaneChangeAction::kMoved;
        Vector3 variance = runs_variance;
        for (int i = 1; i < 3; ++i) {
          if (runs_variance[i] >= kUnconstrainedTilt * kUnconstrainedTilt) {
            variance[i] = prior_variance[i];
          }
        }
        change.reason = fmt::format(
            "{} runs put it {:+.3f} m (sigma {:.3f}) and {:.2f} deg off the map (sigma {:.3f} m "
            "there); chi2 {:.1f} > {:.2f}",
            change.runs_measured, runs[0], std::sqrt(runs_variance[0]),
            tested.tail<2>().norm() / kRadiansPerDegree, prior[0], change.chi2, options.chi2);
        updated = Corrected(updated, tested);
        updated.sigma.offset = std::sqrt(variance[0]);
        updated.sigma.normal = variance.tail<2>().cwiseSqrt();
        change.offset = tested[0];
        change.tilt = tested.tail<2>();
        change.offset_sigma = updated.sigma.offset;
        change.tilt_sigma = updated.sigma.normal;
      } else if (change.chi2 > options.chi2 && large) {
        change.action = PlaneChangeAction::kSuspect;
        change.offset = tested[0];
        change.tilt = tested.tail<2>();
        change.offset_sigma = std::sqrt(runs_variance[0]);
        change.tilt_sigma = runs_variance.tail<2>().cwiseSqrt();
        change.reason =
            !agree ? fmt::format(
                         "{} runs put it {:+.3f} m (sigma {:.3f}) off the map on average, but "
                         "disagree with each other (chi2 {:.1f} of their spread); kept",
                         change.runs_measured, runs[0], std::sqrt(runs_variance[0]), spread)
                   : fmt::format(
                         "{} run(s) of {} sequence(s) put it {:+.3f} m (sigma {:.3f}) and {:.2f} "
                         "deg off the map (chi2 {:.1f} > {:.2f}); kept until runs of {} "
                         "sequences agree (one drive cannot tell its trajectory's error from the "
                         "plane's)",
                         change.runs_measured, sequences.size(), runs[0],
                         std::sqrt(runs_variance[0]), tested.tail<2>().norm() / kRadiansPerDegree,
                         change.chi2, options.chi2, options.min_runs_to_move);
      } else {
        change.action = PlaneChangeAction::kConfirmed;
        change.reason = fmt::format(
            "{} run(s) measured it where the map has it within their uncertainty (chi2 {:.1f} <= "
            "{:.2f}, or below {:.3f} m and {:.1f} deg)",
            change.runs_measured, change.chi2, options.chi2, options.min_offset,
            options.min_tilt_deg);
        change.offset_sigma = updated.sigma.offset;
        change.tilt_sigma = updated.sigma.normal;
      }
    } else {
      change.reason = change.runs_seen > 0 ? "seen, but by too few points to say" : "not seen";
    }
    ++counts[ToString(change.action)];
    if (change.action == PlaneChangeAction::kRetired) {
      retired.push_back(plane.id);
    } else {
      result.planes.planes.push_back(std::move(updated));
    }
    result.changes.push_back(std::move(change));
  }
  nlohmann::json inputs = nlohmann::json::array();
  for (const MapUpdates& update : updates) {
    inputs.push_back({{"file", update.source.string()},
                      {"sequence", update.sequence},
                      {"frames", update.frames},
                      {"planes_fnv1a64", update.planes_hash}});
  }
  nlohmann::json history = map.stats.value("map_update_history", nlohmann::json::array());
  history.push_back({{"base", map.source.string()}, {"inputs", inputs}, {"counts", counts}});
  result.planes.stats["map_update"] = {
      {"base", map.source.string()}, {"inputs", inputs}, {"counts", counts}, {"retired", retired}};
  result.planes.stats["map_update_history"] = history;
  return result;
}

std::string ChangesMarkdown(const PlaneMap& map, const std::vector<MapUpdates>& updates,
                            const MapUpdateResult& result) {
  std::map<std::string, int> counts;
  for (const PlaneChange& change : result.changes) ++counts[ToString(change.action)];
  std::string text = fmt::format("# Map update of {}\n\nRuns fused:\n\n", map.source.string());
  for (const MapUpdates& update : updates) {
    text += fmt::format("- `{}`: {} ({} frames)\n", update.source.string(), update.sequence,
                        update.frames);
  }
  text += fmt::format(
      "\n{} planes: {} moved, {} retired, {} suspect, {} confirmed, {} unchanged.\n\n"
      "| plane | action | runs measured / contradicted / seen | offset (m) | sigma (m) | tilt "
      "(deg) | why |\n|---|---|---|---|---|---|---|\n",
      map.planes.size(), counts["moved"], counts["retired"], counts["suspect"], counts["confirmed"],
      counts["unchanged"]);
  // Moved and retired first: they are what a map maintainer looks at.
  for (const PlaneChangeAction action :
       {PlaneChangeAction::kMoved, PlaneChangeAction::kRetired, PlaneChangeAction::kSuspect,
        PlaneChangeAction::kConfirmed}) {
    for (const PlaneChange& change : result.changes) {
      if (change.action != action) continue;
      text +=
          fmt::format("| {} | {} | {} / {} / {} | {:+.3f} | {:.3f} | {:.2f} | {} |\n", change.id,
                      ToString(change.action), change.runs_measured, change.runs_contradicted,
                      change.runs_seen, change.offset, change.offset_sigma,
                      change.tilt.norm() / kRadiansPerDegree, change.reason);
    }
  }
  return text;
}

}  // namespace planeloc
