// What a run learns about the prior map's planes (`planeloc run --map-update`,
// docs/map-update.md): for each plane, the stereo points that measure it, the points seen through
// it, and the frames it was seen in, summarized at the end as unseen / confirmed / corrected /
// contradicted (io/map_updates.h).
//
// A window point x (its visual estimate, as the plane association uses it) observed from a camera
// at c measures plane k when it is a witness of plane k by the bias statistics' rule
// (PlaneAssociator::WitnessedPlane with half-width `band`, disabled planes included: clear of the
// bands of parallel neighbours, within `band` of no crossing plane), inside k's outline, with a
// sigma along the normal of at most `max_point_sigma`. It is seen through plane k when x and c lie
// on opposite sides of the plane, x more than `band` behind it, and the ray from c to x crosses the
// plane inside its outline: the surface is not there (a torn-down building) or has moved far. The
// latest record of each point counts (points are re-estimated in every window that holds them).
//
// The summary fits s = offset + g1 a1 + g2 a2 to the measuring points (signed distances s, in-plane
// coordinates a1 along the map's major axis and a2 across it, both from the plane's centroid)
// over the inliers of a median / MAD test; the fit's covariance plus the trajectory's own error
// (`trajectory_sigma`, `trajectory_tilt_sigma`: every point of a plane shares the pose error of
// the keyframes that saw it, which no count of points averages away) is the measurement's
// uncertainty. A plane is corrected when the measured (offset, tilt) is beyond the chi-square
// threshold of that uncertainty and larger than min_offset or min_tilt, confirmed otherwise;
// contradicted when more points were seen through it than on it (at least min_points); unseen
// below min_points.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <set>
#include <vector>

#include "planeloc/io/map_updates.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/prior/plane_association.h"

namespace planeloc {

struct PlaneEvidenceOptions {
  double band = 0.6;              // metres (MapUpdate.band)
  double max_point_sigma = 0.15;  // metres, along the normal
  int min_points = 20;            // MapUpdate.minPoints
  // The trajectory's error along a plane's normal and about its axes, shared by all its points
  // (MapUpdate.trajectorySigma, MapUpdate.trajectoryTiltSigmaDeg).
  double trajectory_sigma = 0.03;          // metres
  double trajectory_tilt_sigma_deg = 0.2;  // degrees
  double min_offset = 0.05;                // metres (MapUpdate.minOffset)
  double min_tilt_deg = 0.5;               // degrees (MapUpdate.minTiltDeg)
  double chi2 = 11.34;                     // 3 DoF, 99 % (MapUpdate.chi2)

  void Check() const;  // throws OptionsError naming the field
};

// One window point: its visual estimate and the centre of a camera that observed it.
struct EvidencePoint {
  int point_id = 0;
  PointEstimate estimate;
  Eigen::Vector3d camera_center = Eigen::Vector3d::Zero();
};

class PlaneEvidence {
 public:
  // `associator` decides which planes are used and holds their outlines; it must outlive this.
  PlaneEvidence(const PlaneMap& map, const PlaneAssociator& associator,
                const PlaneEvidenceOptions& options);

  // Records the window of the keyframe at frame index `frame`.
  void ObserveWindow(int frame, const std::vector<EvidencePoint>& points);
  // Notes the planes the associator has disabled by now (the first frame each was disabled at).
  void NoteDisabled(int frame);
  // Forgets the points recorded so far (after a correction of the map frame they measured the
  // trajectory's error as much as the planes'); the frames seen stay.
  void Reset();

  // One entry per plane of the map, in its order.
  std::vector<PlaneUpdate> Summarize() const;

 private:
  struct Sample {
    double a1 = 0, a2 = 0;  // metres, in-plane from the centroid
    double s = 0;           // signed distance, metres
    bool through = false;
  };
  struct PlaneRecord {
    MapPlane plane;
    Eigen::Vector3d e1 = Eigen::Vector3d::Zero(), e2 = Eigen::Vector3d::Zero();
    std::map<int, Sample> samples;  // point id -> latest
    std::set<int> frames;
    std::optional<int> disabled_at_frame;
  };
  PlaneUpdate Summarize(const PlaneRecord& record) const;

  const PlaneAssociator& associator_;
  PlaneEvidenceOptions options_;
  std::vector<PlaneRecord> records_;
  std::map<int, std::size_t> index_by_id_;
  std::vector<int> candidates_;  // scratch
};

}  // namespace planeloc
