// `planeloc map update`: fuses what runs learned about a plane map (io/map_updates.h) into a new
// plane map, and says what changed and why (docs/map-update.md).
//
// Per plane, the runs that measured it (confirmed or corrected) give a correction
// x = (offset, tilt about the major axis, tilt about n x it) with a diagonal covariance R_i; they
// are fused by information, x_r = R_r (sum R_i^-1 x_i), R_r = (sum R_i^-1)^-1. The map's own sigma
// (planes.json) is the prior P0 = diag(sigma_offset^2, sigma_normal^2) about x = 0. Then:
//   - moved: the runs disagree with the map, chi^2 = x_r^T (P0 + R_r)^-1 x_r > chi2, by at least
//     min_offset or min_tilt: the plane is replaced by the runs' estimate and its sigma by R_r
//     (a change is not noise about the old plane, so the old plane is no prior for the new one;
//     a tilt no run constrained keeps the map's);
//     This needs runs of at least min_runs_to_move distinct sequences (2) whose offsets agree with
//     each other (chi^2 of their spread about the mean within its 99 % quantile): otherwise the
//     plane is
//   - suspect: off the map as above, but measured by too few runs or by runs that disagree; kept
//     as it is;
//   - confirmed: measured and consistent: kept as it is, sigma included (the runs' measurements
//     share their trajectories' errors; a posterior mean would move correct planes by them);
//   - retired: more runs saw through it (contradicted) than measured it, at least one;
//   - unchanged: no run measured or contradicted it.
// Each plane's "provenance" gains one entry per input run; stats.map_update lists the inputs and
// counts, and the ids of retired planes (they leave the map).
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "planeloc/io/map_updates.h"
#include "planeloc/io/plane_map.h"

namespace planeloc {

struct MapUpdateOptions {
  // Drives (distinct run sequences) that must have measured a plane before it is moved: one run's
  // measurements of all its planes share that run's trajectory error, which the run cannot tell
  // from the planes' own, and two runs of the same images share most of it.
  int min_runs_to_move = 2;
  double chi2 = 11.34;        // 3 DoF, 99 %
  double min_offset = 0.05;   // metres
  double min_tilt_deg = 0.5;  // degrees
};

enum class PlaneChangeAction { kUnchanged, kConfirmed, kSuspect, kMoved, kRetired };
const char* ToString(PlaneChangeAction action);

struct PlaneChange {
  int id = 0;
  PlaneChangeAction action = PlaneChangeAction::kUnchanged;
  int runs_measured = 0, runs_contradicted = 0, runs_seen = 0;
  // The applied correction (moved, confirmed) and the plane's new sigma.
  double offset = 0;
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();
  double offset_sigma = 0;
  Eigen::Vector2d tilt_sigma = Eigen::Vector2d::Zero();
  double chi2 = 0;     // of the runs against the map (measured planes)
  std::string reason;  // one sentence
};

struct MapUpdateResult {
  PlaneMap planes;                   // the updated map (retired planes removed)
  std::vector<PlaneChange> changes;  // one per plane of the input map, in its order
};

// Checks that `updates` was written by a run on this very plane map: the same file hash, the
// same number of planes, the same frame name, and only ids the map has. Throws InputError naming
// both files (updates.source and map.source).
void CheckUpdatesMatch(const PlaneMap& map, const std::string& planes_hash,
                       const MapUpdates& updates);

// Fuses the runs' updates into the map (checked with CheckUpdatesMatch beforehand).
MapUpdateResult FuseMapUpdates(const PlaneMap& map, const std::vector<MapUpdates>& updates,
                               const MapUpdateOptions& options = {});

// The changes as Markdown: inputs, counts, and one row per moved, confirmed or retired plane.
std::string ChangesMarkdown(const PlaneMap& map, const std::vector<MapUpdates>& updates,
                            const MapUpdateResult& result);

}  // namespace planeloc
