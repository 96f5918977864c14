#include "planeloc/io/trajectory.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <limits>

#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

namespace planeloc {
namespace {

// One non-blank line of a text file with its 1-based line number.
struct NumberLine {
  int line = 0;
  std::vector<double> values;
};

// Splits `text` at whitespace and commas and parses every token as a double. Tokens that are not
// numbers, or that are NaN/Inf, are errors: a silently wrong pose is worse than a clear stop.
std::vector<double> ParseNumbers(const std::string& text, const std::string& path, int line) {
  std::vector<double> values;
  std::size_t pos = 0;
  const auto is_separator = [](char c) {
    return c == ' ' || c == '\t' || c == ',' || c == '\r' || c == '\n';
  };
  while (pos < text.size()) {
    while (pos < text.size() && is_separator(text[pos])) ++pos;
    if (pos >= text.size()) break;
    std::size_t end = pos;
    while (end < text.size() && !is_separator(text[end])) ++end;
    const std::string token = text.substr(pos, end - pos);
    char* parsed_end = nullptr;
    errno = 0;
    const double value = std::strtod(token.c_str(), &parsed_end);
    if (parsed_end != token.c_str() + token.size() || token.empty()) {
      throw InputError(path, line, fmt::format("'{}' is not a number", token),
                       "every value on a pose line must be a decimal number");
    }
    if (!std::isfinite(value)) {
      throw InputError(path, line, fmt::format("value '{}' is not finite (NaN or Inf)", token),
                       "remove or repair the pose; the evaluator needs finite numbers");
    }
    values.push_back(value);
    pos = end;
  }
  return values;
}

std::ifstream OpenForReading(const std::filesystem::path& path, const std::string& what) {
  if (!std::filesystem::exists(path)) {
    throw InputError(path.string(), fmt::format("{} does not exist", what),
                     "check the path (and the current directory)");
  }
  if (std::filesystem::is_directory(path)) {
    throw InputError(path.string(), fmt::format("{} is a directory, not a file", what),
                     "pass the path of the file itself");
  }
  std::ifstream stream(path);
  if (!stream) {
    throw InputError(path.string(), fmt::format("cannot open {}", what),
                     "check that the file is readable");
  }
  return stream;
}

// Reads every non-blank line that does not start with '#' as a list of numbers.
std::vector<NumberLine> ReadNumberLines(const std::filesystem::path& path,
                                        const std::string& what) {
  std::ifstream stream = OpenForReading(path, what);
  std::vector<NumberLine> lines;
  std::string text;
  int line = 0;
  while (std::getline(stream, text)) {
    ++line;
    const auto first = text.find_first_not_of(" \t\r");
    if (first == std::string::npos || text[first] == '#') continue;
    lines.push_back({line, ParseNumbers(text, path.string(), line)});
  }
  if (stream.bad()) {
    throw InputError(path.string(), fmt::format("read error in {}", what),
                     "check the file system and permissions");
  }
  return lines;
}

std::string FormatNumber(double value) { return fmt::format("{}", value); }

std::string KittiLine(const Rigid3d& world_from_cam) {
  const Eigen::Matrix<double, 3, 4> m = world_from_cam.Matrix3x4();
  std::string line;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (!line.empty()) line += ' ';
      line += FormatNumber(m(r, c));
    }
  }
  return line;
}

// The checks every timestamped pose reader applies to one line: a unit quaternion, a time after
// the previous one. `order` says how the file writes its quaternion (for the fix).
void CheckStampedPose(const Eigen::Quaterniond& q, double seconds, const Trajectory& so_far,
                      const std::filesystem::path& path, int line, const std::string& order) {
  if (std::abs(q.norm() - 1.0) > kQuaternionNormTolerance) {
    throw InputError(path.string(), line,
                     fmt::format("|q| = {:.6g}: the quaternion is not a unit quaternion "
                                 "(tolerance {})",
                                 q.norm(), kQuaternionNormTolerance),
                     "write a unit quaternion " + order);
  }
  if (!so_far.timestamps.empty() && seconds <= so_far.timestamps.back()) {
    throw InputError(path.string(), line,
                     fmt::format("timestamp {} is not after the previous one {}", seconds,
                                 so_far.timestamps.back()),
                     "sort the poses by time and remove duplicates");
  }
}

std::string TumLine(double timestamp, const Rigid3d& world_from_cam) {
  const Eigen::Vector3d& t = world_from_cam.translation;
  const Eigen::Quaterniond& q = world_from_cam.rotation;
  return fmt::format("{} {} {} {} {} {} {} {}", FormatNumber(timestamp), FormatNumber(t.x()),
                     FormatNumber(t.y()), FormatNumber(t.z()), FormatNumber(q.x()),
                     FormatNumber(q.y()), FormatNumber(q.z()), FormatNumber(q.w()));
}

}  // namespace

void CheckRotation(const Eigen::Matrix3d& rotation, const std::string& source, int line) {
  const double orthonormality =
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).norm();
  const double determinant = rotation.determinant();
  if (!(orthonormality <= kRotationTolerance) || !(determinant > 0.0)) {
    throw InputError(
        source, line,
        fmt::format("the rotation is not a rotation: |R^T R - I| = {:.3g} (at most {} allowed), "
                    "det R = {:.4f} (must be +1){}",
                    orthonormality, kRotationTolerance, determinant,
                    determinant < 0.0 ? ": a mirrored (left-handed) pose" : ""),
        "write orthonormal rotations with determinant +1 (row-major 3x4 world_from_cam); a "
        "scaled or mirrored pose is not a camera pose");
  }
}

TrajectoryFormat ParseTrajectoryFormat(const std::string& name) {
  if (name == "kitti") return TrajectoryFormat::kKitti;
  if (name == "tum") return TrajectoryFormat::kTum;
  throw InputError("", fmt::format("unknown trajectory format '{}'", name), "use 'kitti' or 'tum'");
}

double Trajectory::PathLength() const {
  double length = 0.0;
  for (std::size_t i = 1; i < world_from_cam.size(); ++i) {
    length += (world_from_cam[i].translation - world_from_cam[i - 1].translation).norm();
  }
  return length;
}

std::vector<Eigen::Matrix<double, 3, 4>> ReadKittiPoseMatrices(const std::filesystem::path& path) {
  std::vector<Eigen::Matrix<double, 3, 4>> poses;
  for (const NumberLine& line : ReadNumberLines(path, "KITTI pose file")) {
    if (line.values.size() != 12) {
      throw InputError(
          path.string(), line.line,
          fmt::format("a KITTI pose line needs 12 numbers, found {}", line.values.size()),
          "write the top 3x4 of world_from_cam row-major, 12 numbers a line");
    }
    Eigen::Matrix<double, 3, 4> m;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 4; ++c) m(r, c) = line.values[4 * r + c];
    }
    CheckRotation(m.leftCols<3>(), path.string(), line.line);
    poses.push_back(m);
  }
  if (poses.empty()) {
    throw InputError(path.string(), "the KITTI pose file holds no poses",
                     "pass a file with one 12-number pose a line");
  }
  return poses;
}

std::vector<double> ReadTimestamps(const std::filesystem::path& path) {
  std::vector<double> stamps;
  for (const NumberLine& line : ReadNumberLines(path, "timestamp file")) {
    if (line.values.size() != 1) {
      throw InputError(path.string(), line.line,
                       fmt::format("a times.txt line needs 1 number, found {}", line.values.size()),
                       "write one timestamp in seconds a line");
    }
    if (!stamps.empty() && line.values[0] <= stamps.back()) {
      throw InputError(path.string(), line.line,
                       fmt::format("timestamp {} is not after the previous one {}", line.values[0],
                                   stamps.back()),
                       "timestamps must increase strictly, one per pose; pass the times.txt of "
                       "this trajectory");
    }
    stamps.push_back(line.values[0]);
  }
  return stamps;
}

Trajectory ReadKittiTrajectory(const std::filesystem::path& path,
                               const std::optional<std::filesystem::path>& times_path) {
  Trajectory trajectory;
  for (const auto& m : ReadKittiPoseMatrices(path)) {
    trajectory.world_from_cam.push_back(Rigid3d::FromMatrix3x4(m));
  }
  if (times_path) {
    trajectory.timestamps = ReadTimestamps(*times_path);
    if (trajectory.timestamps.size() != trajectory.world_from_cam.size()) {
      throw InputError(
          times_path->string(),
          fmt::format("{} timestamps for the {} poses of {}", trajectory.timestamps.size(),
                      trajectory.world_from_cam.size(), path.string()),
          "pass the times.txt of the same sequence (one line per pose)");
    }
  }
  return trajectory;
}

Trajectory ReadTumTrajectory(const std::filesystem::path& path) {
  Trajectory trajectory;
  for (const NumberLine& line : ReadNumberLines(path, "TUM trajectory file")) {
    const auto& v = line.values;
    if (v.size() != 8) {
      throw InputError(path.string(), line.line,
                       fmt::format("a TUM line needs 8 numbers, found {}", v.size()),
                       "write 't tx ty tz qx qy qz qw' a line");
    }
    const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
    CheckStampedPose(q, v[0], trajectory, path, line.line,
                     "qx qy qz qw (TUM order: t tx ty tz qx qy qz qw)");
    trajectory.timestamps.push_back(v[0]);
    trajectory.world_from_cam.emplace_back(q, Eigen::Vector3d(v[1], v[2], v[3]));
  }
  if (trajectory.world_from_cam.empty()) {
    throw InputError(path.string(), "the TUM trajectory file holds no poses",
                     "pass a file with lines 't tx ty tz qx qy qz qw'");
  }
  return trajectory;
}

Trajectory ReadEurocTrajectory(const std::filesystem::path& path) {
  Trajectory trajectory;
  for (const NumberLine& line : ReadNumberLines(path, "EuRoC ground-truth file")) {
    const auto& v = line.values;
    if (v.size() < 8) {
      throw InputError(
          path.string(), line.line,
          fmt::format("a EuRoC ground-truth line needs at least 8 numbers, found {}", v.size()),
          "pass state_groundtruth_estimate0/data.csv or vicon0/data.csv: "
          "'timestamp [ns], p x y z, q w x y z, ...' a line");
    }
    const Eigen::Quaterniond q(v[4], v[5], v[6], v[7]);
    const double seconds = v[0] * 1e-9;  // ns as a double: 256 ns resolution at 1.4e18
    CheckStampedPose(q, seconds, trajectory, path, line.line,
                     "q_w q_x q_y q_z (EuRoC order: w first)");
    trajectory.timestamps.push_back(seconds);
    trajectory.world_from_cam.emplace_back(q, Eigen::Vector3d(v[1], v[2], v[3]));
  }
  if (trajectory.world_from_cam.empty()) {
    throw InputError(path.string(), "the EuRoC ground-truth file holds no poses",
                     "pass state_groundtruth_estimate0/data.csv of a mav0 folder");
  }
  return trajectory;
}

Trajectory ReadTrajectory(const std::filesystem::path& path, TrajectoryFormat format) {
  return format == TrajectoryFormat::kKitti ? ReadKittiTrajectory(path) : ReadTumTrajectory(path);
}

void WriteKittiTrajectory(const std::filesystem::path& path, const Trajectory& trajectory) {
  std::string text;
  for (const Rigid3d& pose : trajectory.world_from_cam) text += KittiLine(pose) + '\n';
  WriteFileWhole(path, text);
}

void WriteTumTrajectory(const std::filesystem::path& path, const Trajectory& trajectory) {
  if (!trajectory.has_timestamps()) {
    throw InputError(path.string(), "a TUM file needs one timestamp per pose",
                     "fill Trajectory::timestamps or write KITTI format");
  }
  std::string text;
  for (std::size_t i = 0; i < trajectory.size(); ++i) {
    text += TumLine(trajectory.timestamps[i], trajectory.world_from_cam[i]) + '\n';
  }
  WriteFileWhole(path, text);
}

TrajectoryWriter::TrajectoryWriter(const std::filesystem::path& path, TrajectoryFormat format)
    : format_(format), file_(std::make_unique<OutputFile>(path, OutputFile::Mode::kIncremental)) {}

TrajectoryWriter::~TrajectoryWriter() = default;

void TrajectoryWriter::Write(double timestamp, const Rigid3d& world_from_cam) {
  file_->Write((format_ == TrajectoryFormat::kKitti ? KittiLine(world_from_cam)
                                                    : TumLine(timestamp, world_from_cam)) +
               '\n');
}

void TrajectoryWriter::Close() { file_->Commit(); }

std::vector<std::pair<std::size_t, std::size_t>> AssociateByTimestamp(
    const std::vector<double>& reference, const std::vector<double>& estimate,
    double max_difference) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  // evo iterates the shorter list and searches the longer one (the estimate is "short" on a tie).
  const bool estimate_longer = estimate.size() > reference.size();
  const std::vector<double>& shorter = estimate_longer ? reference : estimate;
  const std::vector<double>& longer = estimate_longer ? estimate : reference;
  const bool longer_sorted = std::adjacent_find(longer.begin(), longer.end(),
                                                std::greater_equal<double>()) == longer.end();
  for (std::size_t s = 0; s < shorter.size() && !longer.empty(); ++s) {
    std::size_t best = 0;
    double best_difference = std::numeric_limits<double>::infinity();
    // Strictly increasing stamps: the closest is one of the two neighbours of the insertion point,
    // the lower one on a tie (numpy's argmin returns the first minimum). Otherwise scan all.
    std::size_t begin = 0;
    std::size_t end = longer.size();
    if (longer_sorted) {
      const auto it = std::lower_bound(longer.begin(), longer.end(), shorter[s]);
      const std::size_t k = static_cast<std::size_t>(it - longer.begin());
      begin = k == 0 ? 0 : k - 1;
      end = std::min(longer.size(), k + 1);
    }
    for (std::size_t l = begin; l < end; ++l) {
      const double difference = std::abs(longer[l] - shorter[s]);
      if (difference < best_difference) {
        best_difference = difference;
        best = l;
      }
    }
    if (best_difference <= max_difference) {
      pairs.emplace_back(estimate_longer ? s : best, estimate_longer ? best : s);
    }
  }
  if (pairs.empty()) {
    std::string range = "(empty)";
    if (!reference.empty() && !estimate.empty()) {
      range = fmt::format("reference {}..{} s, estimate {}..{} s", reference.front(),
                          reference.back(), estimate.front(), estimate.back());
    }
    throw InputError("", fmt::format("no timestamps match within {} s ({})", max_difference, range),
                     "check that both files use the same clock, or raise --max-diff");
  }
  return pairs;
}

}  // namespace planeloc
