// Accumulation of LiDAR scans into a voxel-downsampled point-cloud map (`planeloc map build`).
// A scan point p (Velodyne frame) goes to the map (= world, the poses' frame) as
//   point_in_world = world_from_cam_i * cam_from_velo * p.
// Downsampling is incremental (each scan, then the whole buffer when it grows), so memory stays
// proportional to the map, not to the number of scans.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/point_cloud.h"
#include "planeloc/io/trajectory.h"

namespace planeloc {

struct MapBuildOptions {
  double voxel_size = 0.10;  // metres, edge of the downsampling voxel (0 = no downsampling)
  int every = 1;             // use every N-th scan
  double min_range = 2.0;    // metres from the sensor: closer points (the car itself) dropped
  double max_range = 60.0;   // metres: farther points (sparse, noisy) dropped
  std::size_t buffer_points = 4'000'000;  // re-downsample the map when this many points pile up
  bool show_progress = true;              // progress bar on stderr (terminal only)
  // The map is written sorted along a Morton curve of cells of this size (metres; 0 = Open3D's
  // hash order). Equal to the default tensor-voting radius, so `map planes` votes on it without
  // making a sorted copy (any other order works, at the cost of that copy).
  double sort_cell = 0.75;

  void Check() const;  // throws OptionsError naming the field
};

// Streams scans into a map. Not thread-safe.
class MapAccumulator {
 public:
  explicit MapAccumulator(MapBuildOptions options);
  // Adds the points of one scan (sensor frame) within [min_range, max_range], moved to the world.
  void AddScan(const std::vector<Eigen::Vector3d>& points_in_velo, const Rigid3d& world_from_velo);
  // Adds points already in the world frame (no range filter), voxel-downsampled like a scan.
  void AddPoints(std::vector<Eigen::Vector3d> points_in_world);
  std::size_t scans() const { return scans_; }
  // Of the scans added: those that gave no point (empty, all NaN/Inf, or all out of range), and
  // the NaN/Inf points dropped (a Velodyne return is never NaN: a damaged file).
  std::size_t empty_scans() const { return empty_scans_; }
  std::size_t non_finite_points() const { return non_finite_points_; }
  std::size_t scan_points() const { return scan_points_; }  // every point handed to AddScan
  std::size_t out_of_range_points() const { return out_of_range_points_; }
  // The downsampled map (world frame). Call once.
  PointCloud Finish();

 private:
  void Compact();

  MapBuildOptions options_;
  std::vector<Eigen::Vector3d> points_;
  std::size_t compacted_size_ = 0;
  std::size_t scans_ = 0;
  std::size_t empty_scans_ = 0;
  std::size_t non_finite_points_ = 0;
  std::size_t scan_points_ = 0;
  std::size_t out_of_range_points_ = 0;
};

// What a map build read and what it dropped: logged, and written into the map file's header
// (PointCloud::comments, behind kMapBuildCommentTag) so that `map planes` can record it in
// planes.json's stats ("map_build") and a map that lost scans says so wherever it goes.
struct MapBuildCounts {
  std::size_t frames = 0;         // frames visited (every --every-th)
  std::size_t missing_scans = 0;  // of those, frames without a scan file
  std::size_t scans = 0;          // scans read
  std::size_t empty_scans = 0;    // scans that gave no point (empty, all NaN/Inf or out of range)
  std::size_t scan_points = 0;    // points in the scans read
  std::size_t non_finite_points = 0;    // NaN/Inf points dropped (a damaged scan file)
  std::size_t out_of_range_points = 0;  // outside [--min-range, --max-range]
  std::size_t map_points = 0;           // in the map, after voxel downsampling

  nlohmann::json ToJson() const;
};
inline constexpr const char* kMapBuildCommentTag = "planeloc map build ";

// The counts of a map file's kMapBuildCommentTag comment (PointCloud::comments) as JSON, or
// nullopt when it has none (a map not made by `map build`) or it is not valid JSON.
std::optional<nlohmann::json> MapBuildCountsFromComments(const std::vector<std::string>& comments);

// Voxel-grid downsampling (io/voxel_filter.h: voxels aligned with the frame origin, centroid per
// voxel), so that `map planes`' default filter at the same voxel size leaves a built map as it is
// (Open3D's VoxelDownSample anchors the grid at the cloud's minimum, which moves from call to
// call); returns the input when voxel_size <= 0.
std::vector<Eigen::Vector3d> VoxelDownsample(const std::vector<Eigen::Vector3d>& points,
                                             double voxel_size);

// The checks of every reader of a sequence's scans: one pose per frame and a LiDAR calibration.
// Returns cam_from_velo; throws InputError naming the sequence folder otherwise.
Rigid3d CheckScanSequence(const KittiSequence& sequence, const Trajectory& poses);

// Reads every options.every-th scan of `sequence` and hands it (Velodyne frame) to `sink` with its
// world_from_velo (poses: world_from_cam per frame). Throws InputError
// if the counts differ, the sequence has no LiDAR calibration or no scan (frames without a scan
// file are skipped with a warning). Shared by BuildMap and the tiled build (map_tiles.h).
// Returns what it visited: the counts' frames, missing_scans and scans (the others stay 0; the
// sink's accumulator knows them).
MapBuildCounts ForEachScan(
    const MapBuildOptions& options, const KittiSequence& sequence, const Trajectory& poses,
    const std::function<void(const std::vector<Eigen::Vector3d>&, const Rigid3d&)>& sink);

// Builds the map of `sequence` with `poses` (world_from_cam of the sequence's left camera, one per
// frame). Throws InputError if the counts differ, the sequence has no LiDAR calibration or no
// scan, or the map ends up empty; frames without a scan file are skipped with a warning. The map's
// comments hold its MapBuildCounts.
PointCloud BuildMap(const MapBuildOptions& options, const KittiSequence& sequence,
                    const Trajectory& poses);

}  // namespace planeloc
