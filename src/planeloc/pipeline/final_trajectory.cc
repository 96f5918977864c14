#include "planeloc/pipeline/final_trajectory.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace planeloc {

std::vector<Rigid3d> ReexpressBeforeLock(const std::vector<Rigid3d>& world_from_cam,
                                         const std::vector<FrameStats>& stats,
                                         const std::vector<LockEvent>& events) {
  if (world_from_cam.size() != stats.size()) {
    throw std::logic_error("ReexpressBeforeLock: one stats record per pose");
  }
  const int frames = static_cast<int>(stats.size());
  // Locked at frame f: its own state, or, for a frame that has none (lost before the state was
  // recorded), the last state before it.
  std::vector<bool> locked(frames, false);
  std::string state;
  for (int f = 0; f < frames; ++f) {
    if (!stats[f].map_lock.empty()) state = stats[f].map_lock;
    locked[f] = state == "locked";
  }
  std::vector<Rigid3d> poses = world_from_cam;
  for (const LockEvent& event : events) {
    if (event.recorrection) continue;
    // The segment's first frame: the one that became its first keyframe (keyframe ids ascend
    // with frames).
    int first_frame = frames;
    for (int f = 0; f < frames; ++f) {
      if (stats[f].keyframe_id && *stats[f].keyframe_id >= event.first_keyframe_id) {
        first_frame = f;
        break;
      }
    }
    for (int f = first_frame; f < std::min(event.frame, frames); ++f) {
      if (!locked[f]) poses[f] = event.map_from_world * poses[f];
    }
  }
  return poses;
}

}  // namespace planeloc
