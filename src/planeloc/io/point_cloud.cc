#include "planeloc/io/point_cloud.h"

#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>

#include <algorithm>
#include <new>
#include <string>

#include "planeloc/io/pcd_reader.h"
#include "planeloc/io/ply_reader.h"
#include "planeloc/io/voxel_filter.h"
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

// Open3D reads .xyz correctly; its .pcd reader misreads double coordinates (SIZE 8 -> bad_alloc)
// and accepts a POINTS larger than the data, hence our own .pcd and .ply parsers.
void ReadXyz(const std::filesystem::path& path, VoxelAccumulator& sink) {
  open3d::geometry::PointCloud o3d_cloud;
  open3d::io::ReadPointCloudOption option;
  option.remove_nan_points = false;  // we reject non-finite points with a message instead
  option.remove_infinite_points = false;
  const bool ok = open3d::io::ReadPointCloud(path.string(), o3d_cloud, option);
  CheckInput(ok, path.string(), 0, "Open3D could not read the point cloud",
             "check the file is a valid .xyz point cloud (x y z per line)");
  sink.Reserve(o3d_cloud.points_.size());
  for (std::size_t i = 0; i < o3d_cloud.points_.size(); ++i) {
    CheckInput(o3d_cloud.points_[i].allFinite(), path.string(), 0,
               "point " + std::to_string(i) + " has a NaN or infinite coordinate",
               "remove invalid points from the map before processing it");
    sink.Add(o3d_cloud.points_[i], nullptr);
  }
}

}  // namespace

PointCloud ReadPointCloud(const std::filesystem::path& path, const PointCloudReadOptions& options) {
  CheckExtension(path);
  CheckInput(std::filesystem::is_regular_file(path), path.string(), 0, "point-cloud file not found",
             "check the path");
  const std::string ext = LowerExtension(path);
  try {
    VoxelAccumulator sink(options.voxel_size);
    std::size_t dropped = 0;
    if (ext == ".pcd") {
      dropped = ReadPcd(path, sink);
    } else if (ext == ".ply") {
      ReadPly(path, sink);
    } else {
      ReadXyz(path, sink);
    }
    PointCloud cloud = sink.Finish();
    cloud.dropped_invalid = dropped;
    CheckInput(!cloud.empty(), path.string(), 0,
               dropped > 0
                   ? "the point cloud is empty (all " + std::to_string(dropped) + " points are NaN)"
                   : "the point cloud is empty (0 points)",
               "give a map with points (e.g. from `planeloc map build`)");
    return cloud;
  } catch (const std::bad_alloc&) {
    throw InputError(path.string(), 0, "map too large for memory",
                     "use --voxel (e.g. --voxel 0.1) to average the points per voxel while "
                     "reading, or crop the map");
  }
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
