// The mapping steps run when a keyframe is inserted, as free functions over the SparseMap:
// new points from the keyframe's stereo matches, culling of recent points, and the local BA
// window (built here, solved by optim/window_ba, applied back by id).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/optim/window_ba.h"
#include "planeloc/tracking/map.h"
#include "planeloc/tracking/odometry_options.h"

namespace planeloc {

// Adds a map point for every unmatched keypoint of the keyframe with a stereo depth below
// close depth, then nearest-first further ones up to far depth, and at least
// `min_new_stereo_points` points in total (ORB-SLAM2 CreateNewKeyFrame). Returns the new ids.
std::vector<int> CreateStereoPoints(SparseMap& map, int keyframe_id, const StereoCamera& camera,
                                    const OdometryOptions& options);

// ORB-SLAM2 MapPointCulling over the recently created points: erase a point whose found/visible
// ratio is below min_found_ratio, or that two keyframes after its creation is observed by fewer
// than min_point_observations keyframes; points older than three keyframes leave the list.
// Returns the number of erased points.
int CullRecentPoints(SparseMap& map, std::vector<int>& recent_point_ids, int current_keyframe_id,
                     const OdometryOptions& options);

// The local BA window around `keyframe_id`: it and its best covisible keyframes are free; other
// keyframes observing the window's points are fixed anchors (the most connected first). The
// first keyframe of the map (the given initial pose) is always fixed, and the oldest window
// keyframe is fixed when nothing else is (gauge freedom). The window has
// options.ba_window_keyframes keyframes, options.ba_window_keyframes_turn at a turn (see
// IsTurning). Visual only: the prior map's half (which points lie on which plane) is added by
// AssociateWindowPlanes (prior/window_planes.h).
WindowProblem BuildLocalWindow(const SparseMap& map, int keyframe_id,
                               const OdometryOptions& options);

// True when the heading changed by more than options.ba_turn_angle_deg between `keyframe_id`
// and the keyframe options.ba_window_keyframes keyframes before it (or the oldest one).
bool IsTurning(const SparseMap& map, int keyframe_id, const OdometryOptions& options);

// The version stamps (Keyframe::version, MapPoint::version) of a window's keyframes and points
// when the window was built, aligned with problem.keyframes and problem.points.
struct WindowSnapshot {
  std::vector<std::uint64_t> keyframe_versions;
  std::vector<std::uint64_t> point_versions;
};
WindowSnapshot SnapshotWindow(const SparseMap& map, const WindowProblem& problem);

struct BaApplyStats {
  int keyframes = 0;                  // poses updated
  int points = 0;                     // positions updated
  int stale_keyframes = 0;            // left as they are: moved since the snapshot
  int stale_points = 0;               // left as they are: moved since the snapshot
  int removed_observations = 0;       // outliers unlinked
  double median_reprojection_px = 0;  // inliers of points seen twice or more
};

// Writes the solution back by id (ids that no longer exist are skipped) and unlinks outlier
// observations. Does nothing when the solution is not usable. With a `snapshot` (a result that
// comes back later than the window was built, from the BA worker), a keyframe or point that was
// moved since the snapshot keeps its newer value, and the outlier flags of its observations
// (computed against the older one) are not used: a late result never undoes a newer change.
BaApplyStats ApplyWindowBa(SparseMap& map, const WindowProblem& problem,
                           const WindowBaResult& result, const StereoCamera& camera,
                           const WindowSnapshot* snapshot = nullptr);

}  // namespace planeloc
