// Trajectory files: KITTI (12 numbers a line, row-major top 3x4 of world_from_cam) and TUM
// (`t tx ty tz qx qy qz qw`, world_from_cam). Errors are planeloc::InputError naming file and line.
#pragma once

#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/geometry/rigid3.h"

namespace planeloc {

enum class TrajectoryFormat { kKitti, kTum };
// "kitti" | "tum"; throws InputError for anything else.
TrajectoryFormat ParseTrajectoryFormat(const std::string& name);

struct Trajectory {
  std::vector<double> timestamps;       // seconds; empty for a KITTI file read without times
  std::vector<Rigid3d> world_from_cam;  // one pose per entry

  std::size_t size() const { return world_from_cam.size(); }
  bool has_timestamps() const { return timestamps.size() == world_from_cam.size(); }
  // Sum of distances between consecutive positions, metres.
  double PathLength() const;
};

// KITTI pose file; `times_path`, when given, is a times.txt with one timestamp per pose.
Trajectory ReadKittiTrajectory(const std::filesystem::path& path,
                               const std::optional<std::filesystem::path>& times_path = {});
Trajectory ReadTumTrajectory(const std::filesystem::path& path);
Trajectory ReadTrajectory(const std::filesystem::path& path, TrajectoryFormat format);

// The rows of a KITTI pose file exactly as written, without the re-orthonormalization that
// Rigid3d applies: this is what evo evaluates, so the evaluator uses it to match evo to 1e-6.
// Same validation and errors as ReadKittiTrajectory.
std::vector<Eigen::Matrix<double, 3, 4>> ReadKittiPoseMatrices(const std::filesystem::path& path);
// A times.txt: one timestamp (seconds) a line; blank lines ignored.
std::vector<double> ReadTimestamps(const std::filesystem::path& path);

void WriteKittiTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);
void WriteTumTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);

// Writes one pose per call and flushes, so a killed run keeps every finished frame.
class TrajectoryWriter {
 public:
  // Throws InputError if the file cannot be opened for writing.
  TrajectoryWriter(const std::filesystem::path& path, TrajectoryFormat format);
  void Write(double timestamp, const Rigid3d& world_from_cam);

 private:
  std::filesystem::path path_;
  TrajectoryFormat format_;
  std::ofstream stream_;
};

// Pairs of indices (reference, estimate) whose timestamps differ by at most `max_difference`
// seconds, matching evo's `associate_trajectories`: every stamp of the shorter list (the estimate
// when both are equally long) is matched to the closest stamp of the longer list (first one on a
// tie) and kept when the difference is <= max_difference. Pairs are ordered by the shorter list.
// Throws InputError when none match.
std::vector<std::pair<std::size_t, std::size_t>> AssociateByTimestamp(
    const std::vector<double>& reference, const std::vector<double>& estimate,
    double max_difference = 0.01);

}  // namespace planeloc
