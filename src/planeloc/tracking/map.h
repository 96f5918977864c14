// The sparse map of the tracker: keyframes and map points in containers keyed by integer id,
// observations both ways (point -> {keyframe id: keypoint index}, keyframe -> point id per
// keypoint) and the covisibility graph (edge weight = number of shared points). Owned by the
// tracking thread only; the BA worker gets copies of the numbers it needs (see pipeline/ba_job.h).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <opencv2/core.hpp>
#include <vector>

#include "planeloc/features/stereo_matcher.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/tracking/frame.h"

namespace planeloc {

struct MapPoint {
  int id = 0;
  Eigen::Vector3d point_in_world = Eigen::Vector3d::Zero();
  cv::Mat descriptor;               // 1 x 32: the observation with the least median distance
  std::map<int, int> observations;  // keyframe id -> keypoint index in that keyframe
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // mean unit viewing direction (world)
  double min_distance = 0, max_distance = 0;          // metres: scale-invariance range
  int first_keyframe_id = 0;                          // keyframe that created the point
  int reference_keyframe_id = 0;
  int visible = 1;  // frames in whose view the point projected
  int found = 1;    // frames that matched it
  // Stamp of the last change of point_in_world (SparseMap::SetPointPosition): a BA result solved
  // from an older stamp must not overwrite the point (see local_mapping.h, ApplyWindowBa).
  std::uint64_t version = 0;
  double FoundRatio() const { return static_cast<double>(found) / visible; }
};

struct Keyframe {
  int id = 0;
  int frame_id = 0;
  double timestamp = 0;
  Rigid3d cam_from_world;
  StereoFeatures features;  // without the image pyramid
  FeatureGrid grid;
  std::vector<int> map_point_ids;   // per left keypoint: map point id or -1
  std::map<int, int> covisibility;  // other keyframe id -> shared points (> 0)
  std::uint64_t version = 0;        // stamp of the last change of cam_from_world (see MapPoint)
  Eigen::Vector3d CameraCenter() const { return cam_from_world.Inverse().translation; }
};

// Pyramid model for the scale-invariance distances of map points.
struct ScaleModel {
  double scale_factor = 1.2;
  int num_levels = 8;
  // Pyramid level at which a point with max_distance is expected at `distance`.
  int PredictLevel(double max_distance, double distance) const;
};

class SparseMap {
 public:
  explicit SparseMap(ScaleModel scale = {}) : scale_(scale) {}

  // A keyframe from a tracked frame: pose and features; no observations yet. Returns its id.
  int AddKeyframe(const Frame& frame);
  // A new point observed by keypoint `keypoint` of keyframe `keyframe_id`. Returns its id.
  int AddPoint(const Eigen::Vector3d& point_in_world, int keyframe_id, int keypoint);
  // Links a point and a keypoint; no-op if the keypoint already observes a point.
  void AddObservation(int point_id, int keyframe_id, int keypoint);
  // Removes the point and its observations.
  void ErasePoint(int point_id);
  void EraseObservation(int point_id, int keyframe_id);
  // Removes a keyframe with its observations and covisibility edges; a point left without
  // observers goes with it. Ids are never reused, so a late BA result that still names the
  // keyframe or such a point skips it (ApplyWindowBa). Returns the ids of the erased points.
  std::vector<int> EraseKeyframe(int keyframe_id);
  // Merges point `drop` into `keep` (ORB-SLAM2 MapPoint::Replace): drop's observations move to
  // keep, except in keyframes that already observe keep (there drop's keypoint is unlinked);
  // visible/found counts add up; drop is erased. keep gets a new version stamp: a BA result
  // solved before the merge (from keep's observations alone) must not overwrite it. The caller
  // updates the covisibility of the keyframes involved.
  void ReplacePoint(int keep, int drop);

  // Recomputes descriptor, normal and distance range from the observations.
  void UpdatePoint(int point_id);
  // Recomputes only normal and distance range (after the point or its observers moved).
  void UpdatePointGeometry(int point_id);
  // Recomputes the covisibility edges of a keyframe (both directions).
  void UpdateConnections(int keyframe_id);
  // Up to `n` covisible keyframes, by weight descending then id ascending.
  std::vector<int> BestCovisible(int keyframe_id, int n) const;
  // Points of a keyframe observed by at least `min_observations` keyframes.
  int NumTrackedPoints(int keyframe_id, int min_observations) const;

  bool HasPoint(int id) const { return points_.count(id) > 0; }
  bool HasKeyframe(int id) const { return keyframes_.count(id) > 0; }
  const MapPoint& point(int id) const { return points_.at(id); }
  MapPoint& mutable_point(int id) { return points_.at(id); }
  const Keyframe& keyframe(int id) const { return keyframes_.at(id); }
  // Move a keyframe or a point; each call gives it a new version stamp (unique in the map).
  void SetKeyframePose(int id, const Rigid3d& cam_from_world);
  void SetPointPosition(int id, const Eigen::Vector3d& point_in_world);

  const std::map<int, Keyframe>& keyframes() const { return keyframes_; }
  const std::map<int, MapPoint>& points() const { return points_; }
  const ScaleModel& scale() const { return scale_; }
  int last_keyframe_id() const { return next_keyframe_id_ - 1; }

 private:
  void UpdateDescriptor(MapPoint& point) const;
  void UpdateNormalAndDistances(MapPoint& point) const;

  ScaleModel scale_;
  std::map<int, Keyframe> keyframes_;
  std::map<int, MapPoint> points_;
  int next_keyframe_id_ = 0;
  int next_point_id_ = 0;
  std::uint64_t next_version_ = 1;  // 0: as created
};

}  // namespace planeloc
