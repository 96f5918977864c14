// A changed world (`planeloc sim --changes`, issue 32): the town as it was when the LiDAR map was
// made and as the cameras see it now. Facades of free-standing buildings moved along their normal
// (renovation), whole buildings removed, new walls built and parked cars that have since left.
// The LiDAR scans the mapping-time world, the cameras the current one; every GT plane carries a
// label saying which change touched it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "planeloc/sim/street.h"
#include "planeloc/sim/town.h"
#include "planeloc/sim/world.h"

namespace planeloc::sim {

// What changes between mapping time and now. All counts are upper bounds: a change needs a site
// near the drive (see ApplyWorldChanges) and is skipped when there is none.
struct WorldChangesOptions {
  double moved_fraction = 0.0;  // share in [0, 1] of the candidate facades that move
  double min_offset = 0.1;      // metres, smallest |shift| of a moved facade along its normal
  double max_offset = 0.5;      // metres, largest |shift|; the sign is drawn (in or out)
  int removed_buildings = 0;    // buildings present at mapping time only
  int new_walls = 0;            // walls present now only
  int parked_cars = 0;          // cars parked at mapping time only

  bool Any() const {
    return moved_fraction > 0.0 || removed_buildings > 0 || new_walls > 0 || parked_cars > 0;
  }
  // The canonical spec ("moved=0.3,offset=0.1:0.5,removed=1,new=1,cars=6"; "none" if !Any()).
  std::string ToSpec() const;
  // Throws InputError naming --changes when a value is out of range.
  void Check() const;
};

// Parses the --changes SPEC: a preset ("renovation", "none") or comma-separated KEY=VALUE items
// with keys moved=FRACTION, offset=MIN:MAX (metres), removed=N, new=N, cars=N (see docs/sim.md).
// Throws InputError naming --changes and the expected form on anything else.
WorldChangesOptions ParseWorldChanges(const std::string& spec);

enum class PlaneChange : std::uint8_t {
  kUnchanged,  // the same plane then and now (its polygon may differ by a moved neighbour)
  kMoved,      // shifted along its normal by PlaneChangeLabel::offset_m
  kRemoved,    // at mapping time only
  kNew,        // now only
};
// "unchanged" | "moved" | "removed" | "new" (the labels of planes_gt.json).
const char* PlaneChangeName(PlaneChange change);

struct PlaneChangeLabel {
  PlaneChange change = PlaneChange::kUnchanged;
  // kMoved: metres along the plane's (mapping-time) unit normal from then to now, so the plane
  // now is n . x + (d - offset_m) = 0. Zero otherwise.
  double offset_m = 0.0;
};

// What ApplyWorldChanges actually did (at most the options' counts).
struct ChangeCounts {
  int moved_facades = 0;
  int removed_buildings = 0;
  int new_walls = 0;
  int parked_cars = 0;  // present at mapping time only
};

struct ChangedWorld {
  World at_mapping;  // what the LiDAR scanned (the planes of the map)
  World now;         // what the cameras see
  // One label per plane id of `now.planes`. Ids are shared: now.planes = at_mapping.planes (moved
  // ones updated; removed ones kept as entries without quads, so ids stay stable) followed by the
  // new walls' planes.
  std::vector<PlaneChangeLabel> labels;
  ChangeCounts counts;
};

// Applies `options` to `town` (built by BuildTown along `street` with `town_options`). Changes
// are drawn only near the drive so that the cameras see them: facades and buildings with a wall
// within 20 m of a camera centre, new walls and cars beside the street within 15 m of one.
// `camera_centres` are in W. Moved facades are ground-level walls (fronts, and side walls shared
// with no neighbour); the walls meeting a moved facade's corners are stretched, and a narrow step
// closes a corner where a neighbour's wall met it, so no box is left open. Removed buildings are
// free-standing ones (no wall shared with a neighbour) for the same reason. Each kind of change
// draws from its own std::mt19937 stream seeded from `seed`, so adding cars does not change which
// facades move.
ChangedWorld ApplyWorldChanges(const World& town, const StreetPath& street,
                               const std::vector<Eigen::Vector3d>& camera_centres,
                               const WorldChangesOptions& options, std::uint32_t seed,
                               const TownOptions& town_options = {});

}  // namespace planeloc::sim
