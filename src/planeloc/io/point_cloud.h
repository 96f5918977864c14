// Point-cloud files (.pcd, .ply, .xyz) read and written through Open3D, with the checks Open3D
// does not do: an empty cloud, NaN/Inf coordinates and .pcd fields we do not understand are
// planeloc::InputError naming the file (Open3D would drop or ignore them silently, and a map that
// silently lost points or misread a field yields a wrong plane map much later).
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

  std::size_t size() const { return points.size(); }
  bool empty() const { return points.empty(); }
  bool has_colors() const { return !colors.empty() && colors.size() == points.size(); }
};

// Field names a .pcd may carry: x y z are required; normal_x/y/z, rgb, rgba, intensity and
// curvature are accepted (only x y z and colours are kept).
bool IsKnownPcdField(const std::string& name);

// Reads .pcd (ascii, binary, binary_compressed), .ply or .xyz by extension. Throws InputError if
// the file is missing, unreadable, has an unknown extension or .pcd field, holds no point, or holds
// a non-finite coordinate (the message gives the first offending point index).
PointCloud ReadPointCloud(const std::filesystem::path& path);

// Writes by extension (.pcd binary, .ply binary, .xyz ascii). Throws InputError if the extension is
// unknown or the file cannot be written.
void WritePointCloud(const std::filesystem::path& path, const PointCloud& cloud);

}  // namespace planeloc
