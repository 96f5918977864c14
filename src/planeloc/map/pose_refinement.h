// Refines the poses a LiDAR map is accumulated with (`planeloc map refine-poses`): poses with
// independent noise of a few centimetres / tenths of a degree (GNSS/INS, or a mapping run's
// output) blur every surface of the map into layers, and the planes fitted to them are off by as
// much. Consecutive scans overlap almost entirely, so point-to-plane ICP between scan i and
// scans i - k (Open3D) measures their relative poses to millimetres; a pose graph
// (optim/pose_graph.h) with the given poses as priors and those relative poses as edges keeps
// the map in the given poses' frame and averages their noise away.
// Registrations that fail (too few correspondences, a jump beyond what the priors allow) are
// dropped and counted.
#pragma once

#include <vector>

#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/map/map_builder.h"
#include "planeloc/optim/pose_graph.h"

namespace planeloc {

struct PoseRefinementOptions {
  double voxel_size = 0.2;          // metres: scans downsampled for ICP
  double normal_radius = 0.6;       // metres: target normals (Open3D, hybrid search, 30 nn)
  double max_correspondence = 0.5;  // metres
  int icp_iterations = 30;
  std::vector<int> neighbours = {1, 3};  // scan i registered to scans i - k
  double min_fitness = 0.3;              // fraction of source points with a correspondence
  // The given poses' noise (priors), per axis.
  double prior_sigma_translation = 0.05;  // metres
  double prior_sigma_rotation_deg = 0.2;
  // A registration's noise (edges), per axis.
  double edge_sigma_translation = 0.01;  // metres
  double edge_sigma_rotation_deg = 0.02;
  // A registration that moves the relative pose farther than this many prior sigmas from the
  // given poses' is taken as failed.
  double max_prior_sigmas = 10.0;
  PoseGraphOptions graph;
  void Check() const;  // throws OptionsError naming the field
};

struct PoseRefinementResult {
  Trajectory poses;  // world_from_cam per frame of the sequence
  int scans = 0, edges = 0, rejected_edges = 0;
  double mean_correction = 0, max_correction = 0;  // metres, refined vs given position
  double mean_correction_deg = 0;
};

// `build` gives the scans used (every, min_range, max_range). Frames without a used scan move
// with the nearest refined frame. Throws InputError as map build does (counts, calibration, no
// scan) and when the pose graph fails.
PoseRefinementResult RefinePoses(const MapBuildOptions& build, const PoseRefinementOptions& options,
                                 const KittiSequence& sequence, const Trajectory& poses);

}  // namespace planeloc
