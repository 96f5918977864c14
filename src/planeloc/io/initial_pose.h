// The initial pose of a run, as a user gives it: 12 numbers on the command line, or the first
// pose of a KITTI or TUM pose file.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "planeloc/geometry/rigid3.h"

namespace planeloc {

// Whitespace-separated numbers; empty when any token is not a whole number.
std::vector<double> ParseNumberList(const std::string& text);
// "12 numbers" (row-major 3x4 world_from_cam). Throws InputError naming --init-pose.
Rigid3d ParsePose12(const std::string& text);
// The first pose of a KITTI (12 numbers a line) or TUM (8 numbers) pose file, detected from
// the first line. Throws InputError naming the file and line.
Rigid3d ReadFirstPose(const std::filesystem::path& path);

}  // namespace planeloc
