// PCL .pcd files (spec: pointclouds.org "The PCD (Point Cloud Data) file format", v0.7), read by
// our own parser so that every header field is checked against the data:
//   DATA ascii | binary | binary_compressed (LZF, fields stored one after another);
//   x y z of TYPE F (SIZE 4 or 8), I or U (any size), COUNT 1; every other field (intensity, rgb,
//   normals, ring, time, PCL's "_" padding, ...) is skipped; rgb/rgba (4 bytes) become colours.
//   Organized clouds (HEIGHT > 1): points with a NaN coordinate (PCL's "no return") are dropped
//   and counted. Unorganized clouds: a non-finite coordinate is an error naming the point.
// Every disagreement between the header and the data (FIELDS vs SIZE/TYPE/COUNT entries, an
// invalid SIZE for a TYPE, WIDTH x HEIGHT vs POINTS, POINTS vs the bytes or lines present, the
// compressed block's sizes) is an InputError naming the file, the header line and both numbers.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "planeloc/io/voxel_filter.h"

namespace planeloc {

// Streams the points of `path` into `sink`; returns the number of NaN points dropped (organized
// clouds only). The header's comment lines but the first ("# .PCD v0.7 ...") go to `comments`
// without their "# ". Throws InputError as described above.
std::size_t ReadPcd(const std::filesystem::path& path, VoxelAccumulator& sink,
                    std::vector<std::string>* comments = nullptr);

}  // namespace planeloc
