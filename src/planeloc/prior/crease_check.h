// The image-side check of the plane map at keyframes (the paper's §III-D/E: LSD line segments
// mark where planes meet in the image).
//
// At a keyframe: LSD (features/line_segments.h) runs on one level of the ORB pyramid; the plane
// map is rendered at the keyframe's pose into a coarse label image (nearest plane per cell,
// from the planes' outlines: the planes' image regions, with occlusion by nearer planes); the
// creases of the map (plane_creases.h: where two planes meet, precise to centimetres) are
// projected, their occluded parts removed, and each visible run is compared with the LSD
// segments: a segment matches when it is within max_angle_deg of the run's direction and
// overlaps it along its length; the run's edge distance is the mean perpendicular distance of the
// nearest matching segment's end points (within search_px); the run is confirmed when segments
// within confirm_px cover at least min_overlap of it. The outlines' own edges are never compared
// with the image: they are only as good as the map's cells.
#pragma once

#include <Eigen/Core>
#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/features/line_segments.h"
#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/prior/plane_creases.h"

namespace planeloc {

struct CreaseCheckOptions {
  PlaneCreaseOptions creases;
  LsdOptions lsd;  // its min_length_px is in level-0 pixels here
  // ORB pyramid level LSD runs on (Planes.lsdLevel); see docs/experiments.md ("LSD level").
  int lsd_level = 1;
  // LSD only on strips along the visible crease runs (Planes.lsdStrips), each resampled so that
  // its run is horizontal: search_px + strip_margin_px to each side, strip_margin_px beyond its
  // ends. Only segments that near a run can match it; the rest of the image is not searched
  // (docs/crease-check.md). False: LSD on the whole level.
  bool lsd_strips = true;
  double strip_margin_px = 8.0;  // level-0 pixels
  int label_downsample = 4;      // label image cell, level-0 pixels
  double near_depth = 0.5;       // metres: nearer geometry is not rendered
  double max_depth = 80.0;       // metres: farther geometry is not rendered
  // Metres, plus occlusion_relative * depth: a crease sample farther than the depth of the
  // (third) plane its cell shows by more than this is occluded.
  double occlusion_margin = 0.1;
  double occlusion_relative = 0.02;
  double min_visible_px = 30.0;  // pixels: shorter visible runs of a crease are not checked
  double max_angle_deg = 3.0;    // LSD segment vs projected crease
  double search_px = 20.0;       // pixels: nearest parallel segment searched within
  double confirm_px = 3.0;       // pixels (Planes.creaseConfirmPx)
  double min_overlap = 0.3;      // fraction of a visible run covered by confirming segments
  int keep_keyframes = 64;       // checks kept (the newest), CreaseChecker::check

  void Check() const;  // throws OptionsError naming the field
};

struct CreaseCheckStats {
  int keyframe_id = -1;  // the keyframe checked (threaded runs report it a few frames later)
  int lsd_segments = 0;
  int visible_planes = 0;                // planes owning at least one label cell
  int visible_creases = 0;               // creases with a visible run
  int confirmed_creases = 0;             // creases with a confirmed run
  int matched_runs = 0;                  // visible runs with a parallel segment within search_px
  std::optional<double> median_edge_px;  // median edge distance of those runs, level-0 pixels
  double ms = 0;                         // LSD + projection + matching
  std::string ToJson() const;            // one JSON object
};

// The planes' image regions at one pose: per cell of label_downsample level-0 pixels, the id of
// the nearest plane (-1: none) and its depth along the cell centre's ray.
struct PlaneLabelImage {
  int downsample = 1;
  cv::Mat plane_id;  // CV_32S
  cv::Mat depth;     // CV_32F, metres; +inf where no plane
  int IdAt(int cell_x, int cell_y) const { return plane_id.at<int>(cell_y, cell_x); }
};

// A visible run of a crease in a keyframe.
struct ProjectedCrease {
  int crease_id = 0;
  int plane_a = 0, plane_b = 0;
  Eigen::Vector2d start = Eigen::Vector2d::Zero(), end = Eigen::Vector2d::Zero();  // level-0 px
  // Where the plane's surface is: +1 left of start->end (cross(end - start, x - start) > 0),
  // -1 right, 0 the crease does not bound it.
  int side_a = 0, side_b = 0;
  std::optional<double> edge_distance_px;
  double overlap = 0;  // fraction of the run covered by segments within confirm_px
  bool confirmed = false;
  // Pixels: where the image shows the crease, relative to the projected line: the mean signed
  // offset (along +90 deg of start->end, as the sides) of the confirming segments, weighted by
  // their overlap.
  double image_offset_px = 0;
};

struct KeyframeCreaseCheck {
  Rigid3d cam_from_world;
  PlaneLabelImage labels;
  std::vector<ProjectedCrease> runs;
  CreaseCheckStats stats;
};

// The label image of `planes` (those with an outline) seen from `cam_from_world`.
PlaneLabelImage RenderPlaneLabels(const std::vector<MapPlane>& planes,
                                  const Rigid3d& cam_from_world, const StereoCamera& camera,
                                  const CreaseCheckOptions& options);
// The visible runs of `creases` (sides filled, not matched yet).
std::vector<ProjectedCrease> ProjectCreases(const std::vector<PlaneCrease>& creases,
                                            const PlaneLabelImage& labels,
                                            const Rigid3d& cam_from_world,
                                            const StereoCamera& camera,
                                            const CreaseCheckOptions& options);
// Fills edge_distance_px, overlap and confirmed of each run from level-0 segments.
void MatchCreases(const std::vector<LineSegment>& segments, const CreaseCheckOptions& options,
                  std::vector<ProjectedCrease>& runs);
// LSD segments of a pyramid level, in level-0 pixels (`image` is the level-0 image resized by
// level0_width / image.cols).
std::vector<LineSegment> DetectSegmentsAtLevel(const cv::Mat& image, int level0_width,
                                               const LsdOptions& options);
// LSD segments on strips of a pyramid level along `runs` (level-0 pixels in and out), see
// CreaseCheckOptions::lsd_strips. Longest first; a segment seen by two overlapping strips is
// reported by both.
std::vector<LineSegment> DetectSegmentsAlongRuns(const cv::Mat& image, int level0_width,
                                                 const std::vector<ProjectedCrease>& runs,
                                                 const CreaseCheckOptions& options);

class CreaseChecker {
 public:
  // Computes the map's creases once; keeps the planes with an outline and area >=
  // options.creases.min_plane_area (or unknown area).
  CreaseChecker(const PlaneMap& map, const CreaseCheckOptions& options);

  // Checks keyframe `keyframe_id` at `cam_from_world` (map frame) against `image`, its left grey
  // image at pyramid level options.lsd_level; keeps the result (the newest keep_keyframes
  // keyframes, check()).
  CreaseCheckStats CheckKeyframe(int keyframe_id, const Rigid3d& cam_from_world,
                                 const StereoCamera& camera, const cv::Mat& image);
  // CheckKeyframe in two steps, so that the expensive one (LSD, rendering, matching) can run on
  // the BA worker: Compute reads only what the constructor set, so it may run on another thread
  // while this thread calls check(); Keep stores the result (this thread).
  KeyframeCreaseCheck Compute(const Rigid3d& cam_from_world, const StereoCamera& camera,
                              const cv::Mat& image) const;
  void Keep(int keyframe_id, KeyframeCreaseCheck check);

  const std::vector<PlaneCrease>& creases() const { return creases_; }
  const KeyframeCreaseCheck* check(int keyframe_id) const;
  const CreaseCheckOptions& options() const { return options_; }

 private:
  CreaseCheckOptions options_;
  std::vector<MapPlane> planes_;
  std::vector<PlaneCrease> creases_;
  std::map<int, KeyframeCreaseCheck> checks_;  // by keyframe id
};

}  // namespace planeloc
