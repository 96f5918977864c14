// Stanford .ply point clouds (spec: paulbourke.net/dataformats/ply), read by our own parser so that
// the header is checked against the data: format ascii, binary_little_endian or binary_big_endian;
// the `vertex` element's x y z of any scalar type (float, double, integers); every other vertex
// property (normals, intensity, ring, time, ...) is skipped; red/green/blue become colours; other
// elements (faces, with list properties) after the vertices are skipped. Fixed-size elements may
// precede `vertex`. A vertex count that disagrees with the bytes or lines present, an unknown
// type or a malformed header is an InputError naming the file and line; a non-finite coordinate
// is an InputError naming the point.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "planeloc/io/voxel_filter.h"

namespace planeloc {

// Streams the vertices of `path` into `sink`; the header's "comment" lines go to `comments`
// without the keyword. Throws InputError as described above.
void ReadPly(const std::filesystem::path& path, VoxelAccumulator& sink,
             std::vector<std::string>* comments = nullptr);

}  // namespace planeloc
