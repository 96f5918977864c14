#include "planeloc/io/point_cloud.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <new>
#include <string>

#include "planeloc/io/pcd_reader.h"
#include "planeloc/io/ply_reader.h"
#include "planeloc/io/voxel_filter.h"
#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "the binary .pcd/.ply writers copy host floats: little-endian hosts only");

namespace planeloc {
namespace {

// The cloud's comments as header lines behind `prefix`; a line break inside one would end the
// comment early and corrupt the header, so it becomes a space.
std::string HeaderComments(const PointCloud& cloud, const char* prefix) {
  std::string lines;
  for (std::string comment : cloud.comments) {
    std::replace(comment.begin(), comment.end(), '\n', ' ');
    std::replace(comment.begin(), comment.end(), '\r', ' ');
    lines += prefix + comment + "\n";
  }
  return lines;
}

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

// .xyz: "x y z" a line (more columns allowed, e.g. intensity, but the same number on every line).
// Our own parser: Open3D's skips lines it cannot read, so a short or garbled line lost a point
// without a word. Blank lines and '#' comments are skipped.
void ReadXyz(const std::filesystem::path& path, VoxelAccumulator& sink) {
  std::ifstream stream(path);
  CheckInput(stream.good(), path.string(), 0, "cannot open the point cloud",
             "check that the file is readable");
  std::string line;
  int number = 0;
  std::size_t columns = 0;
  long long points = 0;
  std::vector<double> values;
  while (std::getline(stream, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    values.clear();
    const char* cursor = line.c_str();
    while (true) {
      while (*cursor == ' ' || *cursor == '\t' || *cursor == ',' || *cursor == '\r') ++cursor;
      if (*cursor == '\0') break;
      char* end = nullptr;
      const double value = std::strtod(cursor, &end);
      const char* token_end = cursor;
      while (*token_end != '\0' && *token_end != ' ' && *token_end != '\t' && *token_end != ',' &&
             *token_end != '\r') {
        ++token_end;
      }
      CheckInput(end == token_end, path.string(), number,
                 fmt::format("'{}' is not a number", std::string(cursor, token_end)),
                 "an .xyz file holds numbers only: x y z a line");
      values.push_back(value);
      cursor = token_end;
    }
    if (columns == 0) {
      CheckInput(values.size() >= 3, path.string(), number,
                 fmt::format("{} values on the line, expected x y z", values.size()),
                 "an .xyz file holds x y z a line (extra columns allowed)");
      columns = values.size();
    }
    CheckInput(values.size() == columns, path.string(), number,
               fmt::format("{} values on the line but the first point's line has {}", values.size(),
                           columns),
               "every line of an .xyz file needs the same columns; the file is truncated or "
               "garbled: re-export it");
    const Eigen::Vector3d point(values[0], values[1], values[2]);
    CheckInput(point.allFinite(), path.string(), number,
               fmt::format("point {} has a NaN or infinite coordinate", points),
               "remove invalid points from the map before processing it");
    sink.Add(point, nullptr);
    ++points;
  }
  CheckInput(!stream.bad(), path.string(), 0, "read error", "check the file and the disk");
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
    std::vector<std::string> comments;
    if (ext == ".pcd") {
      dropped = ReadPcd(path, sink, &comments);
    } else if (ext == ".ply") {
      ReadPly(path, sink, &comments);
    } else {
      ReadXyz(path, sink);
    }
    PointCloud cloud = sink.Finish();
    cloud.dropped_invalid = dropped;
    cloud.comments = std::move(comments);
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
  if (path.has_parent_path()) {
    std::error_code ignored;
    std::filesystem::create_directories(path.parent_path(), ignored);  // OutputFile names it
  }
  // Our own writers (Open3D's ignore failed writes: a full disk gave a 0-byte map and success),
  // through OutputFile: every write checked, the file renamed into place when complete.
  OutputFile file(path, OutputFile::Mode::kWhole);
  const std::string ext = LowerExtension(path);
  const std::size_t n = cloud.size();
  const bool colors = cloud.has_colors();
  const auto rgb = [&](std::size_t i, int channel) {
    return static_cast<std::uint8_t>(
        std::lround(std::clamp(cloud.colors[i][channel], 0.0, 1.0) * 255.0));
  };
  std::string buffer;
  const auto flush_if_full = [&](bool last) {
    if (buffer.size() >= (1u << 20) || (last && !buffer.empty())) {
      file.Write(buffer);
      buffer.clear();
    }
  };
  const auto append = [&buffer](const auto& value) {
    buffer.append(reinterpret_cast<const char*>(&value), sizeof(value));  // host = little endian
  };
  if (ext == ".xyz") {
    for (const Eigen::Vector3d& p : cloud.points) {
      buffer += fmt::format("{} {} {}\n", p.x(), p.y(), p.z());
      flush_if_full(false);
    }
  } else if (ext == ".pcd") {
    // PCL's layout: float x y z, colour packed in the bits of a float "rgb" field.
    buffer = fmt::format(
        "# .PCD v0.7 - Point Cloud Data file format\n{}VERSION 0.7\nFIELDS x y z{}\nSIZE 4 4 4{}\n"
        "TYPE F F F{}\nCOUNT 1 1 1{}\nWIDTH {}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {}\n"
        "DATA binary\n",
        HeaderComments(cloud, "# "), colors ? " rgb" : "", colors ? " 4" : "", colors ? " F" : "",
        colors ? " 1" : "", n, n);
    for (std::size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) append(static_cast<float>(cloud.points[i][k]));
      if (colors) {
        append(static_cast<std::uint32_t>((rgb(i, 0) << 16) | (rgb(i, 1) << 8) | rgb(i, 2)));
      }
      flush_if_full(false);
    }
  } else {  // .ply: double coordinates, uchar colours
    buffer = fmt::format(
        "ply\nformat binary_little_endian 1.0\ncomment planeloc\n{}element vertex {}\n"
        "property double x\nproperty double y\nproperty double z\n{}end_header\n",
        HeaderComments(cloud, "comment "), n,
        colors ? "property uchar red\nproperty uchar green\nproperty uchar blue\n" : "");
    for (std::size_t i = 0; i < n; ++i) {
      for (int k = 0; k < 3; ++k) append(cloud.points[i][k]);
      if (colors) {
        for (int k = 0; k < 3; ++k) append(rgb(i, k));
      }
      flush_if_full(false);
    }
  }
  flush_if_full(true);
  file.Commit();
}

}  // namespace planeloc
