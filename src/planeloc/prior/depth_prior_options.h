// What a user sets about the depth prior (`planeloc run --map-cloud`, DepthPrior.* keys). Apart
// from the residual (depth_prior.h), so that the settings table need not see Ceres.
#pragma once

#include "planeloc/features/dense_stereo.h"

namespace planeloc {

// The map cloud's flat patches as the window BA's planes (cloud_surfaces.h).
struct CloudSurfaceOptions {
  double radius = 0.6;  // m: the cloud points around a map point that define its patch
  int min_points = 8;   // fewer: no patch
  // m: RMS of the patch's points along its normal; thicker is not a surface (foliage, a crease).
  double max_thickness = 0.05;
  // The patch's second extent (sqrt of the middle eigenvalue) over `radius` at least this: a line
  // of points (a pole, a kerb's edge, one scan ring) has no normal.
  double min_spread = 0.25;
  void Check() const;  // throws OptionsError naming the field
};

struct DepthPriorOptions {
  DenseStereoOptions stereo;     // the dense disparity the residual reads
  double voxel_size = 0.2;       // the map cloud is voxelized to this once, when loaded (m)
  double max_range = 40.0;       // map points farther from the camera are not used (m)
  double min_depth = 1.0;        // nor nearer than this along the optical axis (m)
  double disparity_sigma = 1.0;  // sigma_d of the dense disparity, level-0 pixels
  // Information of the depth residuals relative to the ORB reprojections' (both whitened).
  double weight = 0.3;
  int sample_cell = 12;   // at most one map point per cell of this many level-0 px
  int max_points = 1500;  // per frame, spread over the image by sample_cell
  // The map's own occlusion test: every map point covers a disc of voxel_size in the image
  // (a splat); a point deeper than the nearest splat at its pixel by more than
  // 1.5 voxel_size + zbuffer_relative * z is hidden (a back face, a wall behind a pillar).
  double zbuffer_relative = 0.02;
  double occlusion_margin = 1.0;  // m; behind the stereo surface by more: occluded
  // Second differences of the disparity around a point's pixel above this (level-0 px): a depth
  // edge, where the interpolated disparity and its gradient mix two surfaces; not used.
  double edge_tolerance = 1.0;
  double huber = 2.0;   // robust kernel threshold, in sigma_d
  int min_points = 30;  // fewer usable map points: the frame keeps its visual pose
  // A refinement that moves the frame's pose by more than this (m, degrees) from its visual pose
  // is refused and the frame keeps the visual pose (DepthPrior.maxCorrection /
  // maxCorrectionDeg): drift is centimetres per frame, and a jump of metres is the depth term
  // locked on the wrong surfaces (measured: 5.5 m in one frame in a turn of kitti07-like 1, then
  // a lost frame and a relocalization 15 m off, with the window BA visual).
  double max_correction = 0.5;
  double max_correction_deg = 2.0;
  // Kim et al.'s residual in each frame's pose (DepthPrior.frameRefinement); off: no dense
  // stereo at all, the map acts through the window BA's patches only.
  bool frame_refinement = true;
  // The window BA's point-to-patch residuals (DepthPrior.windowSurfaces; cloud_surfaces.h).
  bool window_surfaces = true;
  CloudSurfaceOptions surfaces;
  void Check() const;
};

}  // namespace planeloc
