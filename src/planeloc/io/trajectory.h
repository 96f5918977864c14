// Trajectory files: KITTI (12 numbers a line, row-major top 3x4 of world_from_cam) and TUM
// (`t tx ty tz qx qy qz qw`, world_from_cam). Errors are planeloc::InputError naming file and line.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/geometry/rigid3.h"
#include "planeloc/util/safe_file.h"

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

// Rotations read from pose files must satisfy |R^T R - I|_F <= kRotationTolerance and det R > 0.
// Real KITTI files pass by far: at most 4.0e-7 over poses/00..10.txt and 9.5e-7 for evo's
// KITTI_00_ORB.txt (numpy over ../shared/data, see docs/reliability.md); a scaled, sheared or
// mirrored rotation fails.
inline constexpr double kRotationTolerance = 1e-3;
// TUM quaternions must have |q| within this of 1 (files with 4 decimals are within 2e-4).
inline constexpr double kQuaternionNormTolerance = 1e-2;
// Throws InputError(source, line) naming the defect unless `rotation` is a rotation as above.
void CheckRotation(const Eigen::Matrix3d& rotation, const std::string& source, int line);

// KITTI pose file (rotations checked with CheckRotation); `times_path`, when given, is a times.txt
// with one timestamp per pose.
Trajectory ReadKittiTrajectory(const std::filesystem::path& path,
                               const std::optional<std::filesystem::path>& times_path = {});
Trajectory ReadTumTrajectory(const std::filesystem::path& path);
// EuRoC / ASL ground truth (state_groundtruth_estimate0/data.csv, vicon0/data.csv): comma
// separated, '#' header, 'timestamp [ns], p_x p_y p_z, q_w q_x q_y q_z, ...' (further columns
// ignored), read as evo reads it: seconds, and the body's pose (not a camera's) in world_from_cam.
Trajectory ReadEurocTrajectory(const std::filesystem::path& path);
Trajectory ReadTrajectory(const std::filesystem::path& path, TrajectoryFormat format);

// The rows of a KITTI pose file exactly as written, without the re-orthonormalization that
// Rigid3d applies: this is what evo evaluates, so the evaluator uses it to match evo to 1e-6.
// Same validation and errors as ReadKittiTrajectory.
std::vector<Eigen::Matrix<double, 3, 4>> ReadKittiPoseMatrices(const std::filesystem::path& path);
// A times.txt: one timestamp (seconds) a line, strictly increasing; blank lines ignored.
std::vector<double> ReadTimestamps(const std::filesystem::path& path);

// Whole files (util/safe_file.h): complete or absent.
void WriteKittiTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);
void WriteTumTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);

// Writes one pose per call and flushes, so a killed run keeps every finished frame. Every write
// and the final Close() are checked (util/safe_file.h): a full disk is an InputError naming the
// file and the system's reason, never a silently short trajectory.
class TrajectoryWriter {
 public:
  // Throws InputError if the file cannot be opened for writing.
  TrajectoryWriter(const std::filesystem::path& path, TrajectoryFormat format);
  ~TrajectoryWriter();
  void Write(double timestamp, const Rigid3d& world_from_cam);
  // Closes the file; throws InputError when the close reports a write error.
  void Close();

 private:
  TrajectoryFormat format_;
  std::unique_ptr<OutputFile> file_;
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
