// The trajectory as the run knows it at its end (`planeloc run --out-final`).
//
// Until the map lock the run is visual odometry in the frame of the start prior; each lock
// correction then moves the map into the map frame (map_from_world), and only the frames tracked
// from then on are written in it. A frame tracked before a lock of its segment is here given in
// the frame that lock found: the corrections of the partial and full locks that came after it
// apply to it, in order. A re-registration after the full lock corrects drift, not the frame, and
// applies to no earlier frame; neither does a lock of a later segment (after a loss). Nothing
// else changes: the frames are not smoothed (docs/map-registration.md, "The final trajectory").
#pragma once

#include <vector>

#include "planeloc/geometry/rigid3.h"
#include "planeloc/pipeline/frame_stats.h"

namespace planeloc {

// `world_from_cam` and `stats`: every frame as tracked (same length); `events`: the run's lock
// corrections in the order applied (Tracker::lock_events).
std::vector<Rigid3d> ReexpressBeforeLock(const std::vector<Rigid3d>& world_from_cam,
                                         const std::vector<FrameStats>& stats,
                                         const std::vector<LockEvent>& events);

}  // namespace planeloc
