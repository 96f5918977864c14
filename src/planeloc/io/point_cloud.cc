#include "planeloc/io/point_cloud.h"

#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string_view>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

std::string LowerExtension(const std::filesystem::path& path) {
  std::string ext = path.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return std::tolower(c); });
  return ext;
}

void CheckExtension(const std::filesystem::path& path) {
  const std::string ext = LowerExtension(path);
  CheckInput(ext == ".pcd" || ext == ".ply" || ext == ".xyz", path.string(), 0,
             "unsupported point-cloud extension '" + ext + "'", "use a .pcd, .ply or .xyz file");
}

// Open3D's PCD reader skips fields it does not know, so a cloud whose x/y/z are named differently
// (or whose layout Open3D misreads) would load as garbage; we read the header ourselves first.
void CheckPcdHeader(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  CheckInput(stream.good(), path.string(), 0, "cannot open the point cloud",
             "check the path and permissions");
  std::string line;
  int line_number = 0;
  bool has_fields = false;
  while (std::getline(stream, line) && line_number < 64) {
    ++line_number;
    std::istringstream tokens(line);
    std::string key;
    tokens >> key;
    if (key == "FIELDS") {
      has_fields = true;
      std::array<bool, 3> xyz = {false, false, false};
      std::string field;
      while (tokens >> field) {
        CheckInput(IsKnownPcdField(field), path.string(), line_number,
                   "unknown .pcd field '" + field + "'",
                   "keep only x y z (optionally normal_x/y/z, rgb, rgba, intensity, curvature), "
                   "e.g. by re-saving the cloud with those fields");
        if (field == "x") xyz[0] = true;
        if (field == "y") xyz[1] = true;
        if (field == "z") xyz[2] = true;
      }
      CheckInput(xyz[0] && xyz[1] && xyz[2], path.string(), line_number,
                 "the .pcd has no x, y and z fields", "write the point coordinates as x y z");
    }
    if (key == "POINTS") {
      long long count = -1;
      tokens >> count;
      CheckInput(count != 0, path.string(), line_number, "the point cloud is empty (0 points)",
                 "give a map with points (e.g. from `planeloc map build`)");
    }
    if (key == "DATA") break;
  }
  CheckInput(has_fields, path.string(), 0, "not a .pcd file (no FIELDS line in the header)",
             "check the file is a PCL .pcd point cloud");
}

}  // namespace

bool IsKnownPcdField(const std::string& name) {
  // "_" is PCL's padding field.
  static const std::array<std::string_view, 11> kKnown = {
      "x",   "y",    "z",         "normal_x",  "normal_y", "normal_z",
      "rgb", "rgba", "intensity", "curvature", "_"};
  return std::find(kKnown.begin(), kKnown.end(), name) != kKnown.end();
}

PointCloud ReadPointCloud(const std::filesystem::path& path) {
  CheckExtension(path);
  CheckInput(std::filesystem::is_regular_file(path), path.string(), 0, "point-cloud file not found",
             "check the path");
  if (LowerExtension(path) == ".pcd") CheckPcdHeader(path);
  open3d::geometry::PointCloud o3d_cloud;
  open3d::io::ReadPointCloudOption option;
  option.remove_nan_points = false;  // we reject non-finite points with a message instead
  option.remove_infinite_points = false;
  const bool ok = open3d::io::ReadPointCloud(path.string(), o3d_cloud, option);
  CheckInput(ok, path.string(), 0, "Open3D could not read the point cloud",
             "check the file is a valid .pcd/.ply/.xyz point cloud");
  CheckInput(!o3d_cloud.points_.empty(), path.string(), 0, "the point cloud is empty (0 points)",
             "give a map with points (e.g. from `planeloc map build`)");
  for (std::size_t i = 0; i < o3d_cloud.points_.size(); ++i) {
    CheckInput(o3d_cloud.points_[i].allFinite(), path.string(), 0,
               "point " + std::to_string(i) + " has a NaN or infinite coordinate",
               "remove invalid points from the map before processing it");
  }
  PointCloud cloud;
  cloud.points = std::move(o3d_cloud.points_);
  if (o3d_cloud.colors_.size() == cloud.points.size()) cloud.colors = std::move(o3d_cloud.colors_);
  return cloud;
}

void WritePointCloud(const std::filesystem::path& path, const PointCloud& cloud) {
  CheckExtension(path);
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  open3d::geometry::PointCloud o3d_cloud;
  o3d_cloud.points_ = cloud.points;
  if (cloud.has_colors()) o3d_cloud.colors_ = cloud.colors;
  open3d::io::WritePointCloudOption option;
  option.write_ascii = open3d::io::WritePointCloudOption::IsAscii::Binary;
  option.compressed = open3d::io::WritePointCloudOption::Compressed::Uncompressed;
  const bool ok = open3d::io::WritePointCloud(path.string(), o3d_cloud, option);
  CheckInput(ok, path.string(), 0, "could not write the point cloud",
             "check the folder exists and is writable");
}

}  // namespace planeloc
