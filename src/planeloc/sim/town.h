// Procedural town along a street centre line: ground, raised sidewalks with curbs, lane
// markings, buildings (box facades with varied widths, heights, set-backs, gaps and corners),
// trees, poles with signs and parked cars; or, with TownOptions::rural, a country road. Fully
// determined by the street and the seed.
#pragma once

#include <cstdint>

#include "planeloc/sim/street.h"
#include "planeloc/sim/world.h"

namespace planeloc::sim {

struct TownOptions {
  double road_half_width = 5.0;  // metres, centre line to curb (two 3.5 m lanes + margins)
  double sidewalk_width = 3.0;   // metres, curb to the nearest possible facade
  double max_setback = 4.0;      // metres, facades stand 0..max_setback behind the sidewalk
  double curb_height = 0.12;     // metres, sidewalk top above the road
  double ground_margin = 150.0;  // metres of ground around the street (beyond LiDAR range)
  bool clutter = true;           // trees, poles, parked cars
  // A country road instead of a street (`sim --preset rural`): no sidewalks, kerbs or parked cars;
  // stretches of cutting (uneven grassy slopes rising beside the road, no plane of a facade's
  // size) or open fields with a rare farm building far back; crash barriers; trees on the slopes
  // and in the fields.
  bool rural = false;
  void Check() const;
};

World BuildTown(const StreetPath& street, std::uint32_t seed, const TownOptions& options = {});

// A parked car as clutter: a body box and a cabin box, the body's bottom centre 0.22 m above
// `position` (W's xy, on the road), `heading` in radians about z, `style` the paint variation.
void AddParkedCar(World& world, const Eigen::Vector2d& position, double heading, int style);

}  // namespace planeloc::sim
