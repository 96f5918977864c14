#include "planeloc/io/initial_pose.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "planeloc/io/trajectory.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// A pose from 12 numbers; `source`/`line` name where they came from in the errors.
Rigid3d FromTwelve(const std::vector<double>& v, const std::string& source, int line) {
  Eigen::Matrix<double, 3, 4> m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = v[r * 4 + c];
  }
  CheckInput(m.allFinite(), source, line, "the initial pose holds a NaN or infinite value",
             "give a finite row-major 3x4 world_from_cam");
  CheckRotation(m.leftCols<3>(), source, line);  // io/trajectory.h: the pose files' tolerance
  return Rigid3d::FromMatrix3x4(m);
}

}  // namespace

std::vector<double> ParseNumberList(const std::string& text) {
  std::istringstream in(text);
  std::vector<double> numbers;
  std::string token;
  while (in >> token) {
    try {
      std::size_t used = 0;
      numbers.push_back(std::stod(token, &used));
      if (used != token.size()) return {};
    } catch (const std::exception&) {
      return {};
    }
  }
  return numbers;
}

Rigid3d ParsePose12(const std::string& text) {
  const std::vector<double> v = ParseNumberList(text);
  CheckInput(v.size() == 12, "", 0,
             "--init-pose needs 12 numbers (row-major 3x4 world_from_cam), got \"" + text + "\"",
             "pass e.g. --init-pose \"1 0 0 0 0 1 0 0 0 0 1 0\"");
  return FromTwelve(v, "--init-pose", 0);
}

Rigid3d ReadFirstPose(const std::filesystem::path& path) {
  std::ifstream in(path);
  CheckInput(in.good(), path.string(), 0, "cannot open the pose file",
             "check the path given to --init-pose-from");
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    const std::vector<double> v = ParseNumberList(line);
    if (v.size() == 12) return FromTwelve(v, path.string(), number);
    if (v.size() == 8) {
      const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
      CheckInput(std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); }),
                 path.string(), number, "the initial pose holds a NaN or infinite value",
                 "write a finite TUM line: t tx ty tz qx qy qz qw");
      CheckInput(std::abs(q.norm() - 1.0) <= kQuaternionNormTolerance, path.string(), number,
                 fmt::format("|q| = {:.6g}: not a unit quaternion", q.norm()),
                 "write a valid TUM line: t tx ty tz qx qy qz qw (unit quaternion)");
      return Rigid3d(q.normalized(), Eigen::Vector3d(v[1], v[2], v[3]));
    }
    throw InputError(path.string(), number,
                     "expected a KITTI pose (12 numbers) or a TUM pose (8 numbers)",
                     "pass a KITTI or TUM trajectory file");
  }
  throw InputError(path.string(), 0, "the pose file holds no pose", "pass a non-empty file");
}

}  // namespace planeloc
