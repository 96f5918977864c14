// Keeping the sparse map small on long drives (issue 11): ORB-SLAM2's keyframe culling and
// map-point fusion (LocalMapping::KeyFrameCulling, SearchInNeighbors), and forgetting keyframes
// far behind the car. Without loop closing nothing reaches a keyframe that no recent keyframe
// shares points with, yet before this every keyframe kept its ~2000 keypoints, descriptors and
// grid and every point its observations for the whole run: memory grew linearly with distance.
#pragma once

#include <set>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/tracking/map.h"

namespace planeloc {

struct MapMaintenanceOptions {
  // A keyframe covisible with the new one is erased when more than cull_redundant_ratio of its
  // close stereo points are each seen by at least cull_min_observers other keyframes at the same
  // or a finer pyramid level (+1) (ORB-SLAM2: 0.9, 3) (Mapping.cullKeyframes,
  // Mapping.cullRedundantRatio, Mapping.cullMinObservers).
  bool cull_keyframes = true;
  double cull_redundant_ratio = 0.9;
  int cull_min_observers = 3;
  // The newest keyframes are never culled: they make the current BA window and the local map
  // that tracking matches against (Mapping.cullKeepNewest).
  int cull_keep_newest = 5;
  // Duplicate points merged at each keyframe: the new keyframe's points projected into its
  // fuse_neighbours best covisible keyframes (and 5 of each one's own best), and theirs into
  // it; a match within fuse_radius (pixels at level 0, times the level's scale) that passes the
  // reprojection chi-square and descriptor tests is merged into the point with more
  // observations (ORB-SLAM2 Fuse, th = 3) (Mapping.fusePoints, Mapping.fuseNeighbours,
  // Mapping.fuseRadius). Over 13 simulated drives (VO, --deterministic) it cut the ATE on 10
  // (geometric mean 0.71x) and plane mode's on 5 of 7 (0.78x) (docs/experiments.md, "Point
  // fusion: visual odometry over 13 drives").
  bool fuse_points = true;
  int fuse_neighbours = 10;
  double fuse_radius = 3.0;
  // Keyframes kept at most (besides the first): beyond that the oldest are erased with the
  // points only they observe (Mapping.keepKeyframes; 0: keep every keyframe). Must exceed what
  // the local map and the BA window reach back (OdometryOptions::Check).
  int keep_keyframes = 300;

  void Check() const;  // throws OptionsError naming the field
};

// ORB-SLAM2 KeyFrameCulling over the keyframes covisible with `keyframe_id`, except the first
// keyframe of the map, the options.cull_keep_newest newest keyframes and `keep` (e.g. the
// tracker's reference keyframe, a keyframe whose BA is still to be built). A keyframe counts
// its map points with a stereo depth in (0, close_depth]; one of them is redundant when at least
// options.cull_min_observers other keyframes observe it at a pyramid level <= its own + 1.
// Returns the erased keyframe ids, ascending.
std::vector<int> CullRedundantKeyframes(SparseMap& map, int keyframe_id, double close_depth,
                                        const MapMaintenanceOptions& options,
                                        const std::set<int>& keep = {});

// Merges duplicates between `keyframe_id` and its neighbours (see MapMaintenanceOptions) and
// updates the keyframe's covisibility. Returns the ids of the points merged away (erased).
std::vector<int> FuseWithNeighbours(SparseMap& map, int keyframe_id, const StereoCamera& camera,
                                    const MapMaintenanceOptions& options);

// Fuses the points `point_ids` into keyframe `target_id` (one direction of FuseWithNeighbours):
// a point not yet observed by the target that matches a free keypoint becomes observed by it; one
// that matches a keypoint with a point is merged with that point (the one with more observations
// survives). Points merged away are appended to `dropped`. Returns the number of fusions.
int FuseIntoKeyframe(SparseMap& map, int target_id, const std::vector<int>& point_ids,
                     const StereoCamera& camera, double radius, std::vector<int>* dropped);

// Erases the oldest keyframes (never the first one, nor `keep`) until at most
// options.keep_keyframes remain besides the first. Returns the erased keyframe ids.
std::vector<int> ForgetOldKeyframes(SparseMap& map, const MapMaintenanceOptions& options,
                                    const std::set<int>& keep = {});

}  // namespace planeloc
