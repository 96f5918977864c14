// Point-cloud files (.pcd, .ply, .xyz) as LiDAR mapping tools write them. .pcd and .ply are read
// by our own parsers (pcd_reader.h, ply_reader.h: every variant, float or double coordinates,
// extra fields skipped, header checked against the data), .xyz by ours too (same columns on
// every line, line numbers in errors); everything is written by our own writers. An empty cloud,
// NaN/Inf coordinates (except the NaN "no return" points of an organized .pcd, which are dropped
// and counted) and a header that disagrees with the data are planeloc::InputError naming the file:
// a map that silently lost points or misread a field yields a wrong plane map much later.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace planeloc {

// A point cloud in the frame its owner names (the LiDAR map: map frame, metres).
struct PointCloud {
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3d> colors;  // RGB in [0, 1]; empty or one per point
  // Reading statistics (0 for a cloud not read from a file):
  std::size_t source_points = 0;    // valid points in the file, before any voxel filter
  std::size_t dropped_invalid = 0;  // NaN points of an organized .pcd, dropped
  // Header comments, one line each (.pcd "# ..." lines after the first, .ply "comment ..."
  // lines): written and read back, so that a map carries how it was made (`map build` records
  // its scan and point counts here, map/map_builder.h). .xyz has no header: none.
  std::vector<std::string> comments;

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_colors() const { return !colors.empty() && colors.size() == points.size(); }
};

struct PointCloudReadOptions {
  // Metres; > 0 averages the points per voxel while reading (voxel_filter.h), so the memory
  // follows the number of voxels, not of points. 0 keeps every point.
  double voxel_size = 0.0;
};

// Reads .pcd (ascii, binary, binary_compressed), .ply (ascii, binary little/big endian) or .xyz by
// extension. Throws InputError if the file is missing, unreadable, has an unknown extension, holds
// no point, disagrees with its header or holds a non-finite coordinate (naming the first
// offending point), and "map too large for memory" when the points do not fit in memory.
PointCloud ReadPointCloud(const std::filesystem::path& path,
                          const PointCloudReadOptions& options = {});

// Writes by extension (.pcd binary float x y z [+ rgb], .ply binary little-endian double x y z
// [+ uchar red green blue], .xyz ascii) as a whole file (util/safe_file.h): complete or absent.
// Throws InputError if the extension is unknown or a write fails (the path and strerror).
void WritePointCloud(const std::filesystem::path& path, const PointCloud& cloud);

}  // namespace planeloc
