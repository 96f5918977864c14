// KITTI / TUM trajectory files: round trips, the per-pose flushing writer, evo-style timestamp
// association and the bad-input errors (file, line and fix in the message).
#include "planeloc/io/trajectory.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <fstream>
#include <string>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"
#include "planeloc/util/test_data.h"

namespace planeloc {
namespace {

void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

Trajectory SampleTrajectory() {
  Trajectory trajectory;
  for (int i = 0; i < 5; ++i) {
    const Eigen::Quaterniond rotation(
        Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d(0.2, 1.0, 0.1).normalized()));
    trajectory.world_from_cam.emplace_back(rotation, Eigen::Vector3d(0.5 * i, -0.01 * i, 1.3 * i));
    trajectory.timestamps.push_back(1317384506.5 + 0.1 * i);
  }
  return trajectory;
}

// Returns the InputError thrown by `call`, failing the test if none is thrown.
template <typename Call>
InputError CatchInputError(Call call) {
  try {
    call();
  } catch (const InputError& e) {
    return e;
  }
  ADD_FAILURE() << "no InputError thrown";
  return InputError("", "", "");
}

TEST(TrajectoryTest, KittiRoundTripIsExact) {
  const TempDir dir;
  const Trajectory trajectory = SampleTrajectory();
  WriteKittiTrajectory(dir.path() / "poses.txt", trajectory);
  const Trajectory read = ReadKittiTrajectory(dir.path() / "poses.txt");
  ASSERT_EQ(read.size(), trajectory.size());
  EXPECT_FALSE(read.has_timestamps());
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_TRUE(
        read.world_from_cam[i].Matrix4d().isApprox(trajectory.world_from_cam[i].Matrix4d(), 1e-15));
  }
  const auto rows = ReadKittiPoseMatrices(dir.path() / "poses.txt");
  EXPECT_EQ(rows[3], trajectory.world_from_cam[3].Matrix3x4());  // shortest round-trip format
  EXPECT_NEAR(read.PathLength(), 4 * std::sqrt(0.25 + 0.0001 + 1.69), 1e-12);
}

TEST(TrajectoryTest, TumRoundTripKeepsTimestamps) {
  const TempDir dir;
  const Trajectory trajectory = SampleTrajectory();
  WriteTumTrajectory(dir.path() / "poses.tum", trajectory);
  const Trajectory read = ReadTumTrajectory(dir.path() / "poses.tum");
  ASSERT_EQ(read.size(), trajectory.size());
  ASSERT_TRUE(read.has_timestamps());
  for (std::size_t i = 0; i < read.size(); ++i) {
    EXPECT_EQ(read.timestamps[i], trajectory.timestamps[i]);
    EXPECT_TRUE(
        read.world_from_cam[i].translation.isApprox(trajectory.world_from_cam[i].translation));
    EXPECT_NEAR(
        RotationAngle(read.world_from_cam[i].rotation, trajectory.world_from_cam[i].rotation), 0.0,
        1e-12);
  }
  EXPECT_EQ(ReadTrajectory(dir.path() / "poses.tum", ParseTrajectoryFormat("tum")).size(), 5u);
  EXPECT_THROW(ParseTrajectoryFormat("euroc"), InputError);
}

TEST(TrajectoryTest, KittiTimesFileIsAttached) {
  const TempDir dir;
  WriteKittiTrajectory(dir.path() / "poses.txt", SampleTrajectory());
  WriteText(dir.path() / "times.txt", "0.0\n0.1\n0.2\n0.3\n0.4\n");
  const Trajectory read = ReadKittiTrajectory(dir.path() / "poses.txt", dir.path() / "times.txt");
  ASSERT_TRUE(read.has_timestamps());
  EXPECT_DOUBLE_EQ(read.timestamps[4], 0.4);

  WriteText(dir.path() / "short_times.txt", "0.0\n0.1\n");
  const InputError e = CatchInputError(
      [&] { ReadKittiTrajectory(dir.path() / "poses.txt", dir.path() / "short_times.txt"); });
  EXPECT_NE(std::string(e.what()).find("short_times.txt"), std::string::npos);
  EXPECT_NE(std::string(e.what()).find("2 timestamps for the 5 poses"), std::string::npos);
}

TEST(TrajectoryTest, WriterFlushesEveryPose) {
  const TempDir dir;
  const Trajectory trajectory = SampleTrajectory();
  TrajectoryWriter kitti(dir.path() / "k.txt", TrajectoryFormat::kKitti);
  TrajectoryWriter tum(dir.path() / "t.txt", TrajectoryFormat::kTum);
  for (std::size_t i = 0; i < 3; ++i) {
    kitti.Write(trajectory.timestamps[i], trajectory.world_from_cam[i]);
    tum.Write(trajectory.timestamps[i], trajectory.world_from_cam[i]);
  }
  // Read while the writers are still open: every written pose must already be on disk.
  EXPECT_EQ(ReadKittiTrajectory(dir.path() / "k.txt").size(), 3u);
  const Trajectory tum_read = ReadTumTrajectory(dir.path() / "t.txt");
  ASSERT_EQ(tum_read.size(), 3u);
  EXPECT_EQ(tum_read.timestamps[2], trajectory.timestamps[2]);
  EXPECT_THROW(TrajectoryWriter(dir.path() / "missing" / "x.txt", TrajectoryFormat::kKitti),
               InputError);
}

TEST(TrajectoryTest, BadLinesNameFileAndLine) {
  const TempDir dir;
  const std::string good = "1 0 0 0 0 1 0 0 0 0 1 0\n";
  WriteText(dir.path() / "eleven.txt", good + "\n1 0 0 1 0 1 0 0 0 0 1\n");
  InputError e = CatchInputError([&] { ReadKittiTrajectory(dir.path() / "eleven.txt"); });
  EXPECT_EQ(e.line(), 3);  // blank lines count
  EXPECT_NE(std::string(e.what()).find("eleven.txt:3"), std::string::npos);
  EXPECT_NE(e.problem().find("found 11"), std::string::npos);
  EXPECT_FALSE(e.fix().empty());

  WriteText(dir.path() / "nan.txt", good + "nan 0 0 1 0 1 0 0 0 0 1 0\n");
  e = CatchInputError([&] { ReadKittiTrajectory(dir.path() / "nan.txt"); });
  EXPECT_EQ(e.line(), 2);
  EXPECT_NE(e.problem().find("not finite"), std::string::npos);

  WriteText(dir.path() / "inf.txt", good + "1 0 0 inf 0 1 0 0 0 0 1 0\n");
  EXPECT_EQ(CatchInputError([&] { ReadKittiTrajectory(dir.path() / "inf.txt"); }).line(), 2);

  WriteText(dir.path() / "word.txt", good + "1 0 0 x 0 1 0 0 0 0 1 0\n");
  EXPECT_EQ(CatchInputError([&] { ReadKittiTrajectory(dir.path() / "word.txt"); }).line(), 2);

  WriteText(dir.path() / "tum7.txt", "# comment\n0.0 0 0 0 0 0 1\n");
  e = CatchInputError([&] { ReadTumTrajectory(dir.path() / "tum7.txt"); });
  EXPECT_EQ(e.line(), 2);

  WriteText(dir.path() / "backwards.txt", "1.0 0 0 0 0 0 0 1\n0.5 0 0 0 0 0 0 1\n");
  EXPECT_EQ(CatchInputError([&] { ReadTumTrajectory(dir.path() / "backwards.txt"); }).line(), 2);

  WriteText(dir.path() / "empty.txt", "\n");
  EXPECT_THROW(ReadKittiTrajectory(dir.path() / "empty.txt"), InputError);
  e = CatchInputError([&] { ReadKittiTrajectory(dir.path() / "missing.txt"); });
  EXPECT_NE(std::string(e.what()).find("missing.txt"), std::string::npos);
  EXPECT_THROW(ReadKittiTrajectory(dir.path()), InputError);  // a directory
}

TEST(TrajectoryTest, RotationsThatAreNotRotationsNameFileAndLine) {
  TempDir dir;
  const auto path = dir.path() / "bad.txt";
  const std::string identity = "1 0 0 0 0 1 0 0 0 0 1 0\n";
  for (const char* line : {"2 0 0 1 0 2 0 0 0 0 2 0",           // scaled
                           "-1 0 0 1 0 1 0 0 0 0 1 0",          // mirrored
                           "1 0.1 0 1 0 1 0 0 0 0 1 0",         // sheared
                           "1.01 0 0 1 0 1.01 0 0 0 0 1.01 0",  // 1 % scale
                           "0 0 0 1 0 0 0 0 0 0 0 0"}) {
    WriteText(path, identity + std::string(line) + "\n");
    const InputError e = CatchInputError([&] { ReadKittiTrajectory(path); });
    EXPECT_EQ(e.path(), path.string()) << line;
    EXPECT_EQ(e.line(), 2) << line;
  }
  // TUM: a non-unit quaternion.
  WriteText(path, "0 0 0 0 0 0 0 1\n0.1 0 0 0 0 0 0 2\n");
  EXPECT_EQ(CatchInputError([&] { ReadTumTrajectory(path); }).line(), 2);
}

TEST(TrajectoryTest, RealKittiGroundTruthPassesTheRotationCheck) {
  PLANELOC_SHARED_DATA_OR_SKIP(poses, "kitti-odometry-gt/poses");
  // Measured: |R^T R - I| at most 4.0e-7 over 00..10 (numpy), 2500x below kRotationTolerance.
  for (int sequence = 0; sequence <= 10; ++sequence) {
    const auto path = poses / fmt::format("{:02d}.txt", sequence);
    EXPECT_NO_THROW(EXPECT_GT(ReadKittiPoseMatrices(path).size(), 0u)) << path;
  }
}

TEST(TrajectoryTest, TimesMustIncrease) {
  TempDir dir;
  const auto times = dir.path() / "times.txt";
  WriteText(times, "0.0\n0.2\n0.1\n");
  const InputError e = CatchInputError([&] { ReadTimestamps(times); });
  EXPECT_EQ(e.line(), 3);
  WriteText(times, "0\n0\n");
  EXPECT_EQ(CatchInputError([&] { ReadTimestamps(times); }).line(), 2);
}

TEST(TrajectoryTest, WriterReportsAFullDisk) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  TrajectoryWriter writer("/dev/full", TrajectoryFormat::kKitti);
  const InputError e = CatchInputError([&] { writer.Write(0.0, Rigid3d::Identity()); });
  EXPECT_EQ(e.path(), "/dev/full");
  EXPECT_NE(std::string(e.what()).find("No space left on device"), std::string::npos) << e.what();
}

TEST(TrajectoryTest, AssociationMatchesEvo) {
  // Estimate shorter: every estimate stamp finds its closest reference stamp within 0.01 s.
  const std::vector<double> reference = {0.0, 0.1, 0.2, 0.3, 0.4};
  const std::vector<double> estimate = {0.101, 0.205, 0.33, 0.399};
  const auto pairs = AssociateByTimestamp(reference, estimate);
  using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;
  EXPECT_EQ(pairs, (Pairs{{1, 0}, {2, 1}, {4, 3}}));
  // Estimate longer: evo iterates the reference instead; ties go to the first stamp.
  // (Binary-exact stamps so the tie at 0.5 is a real tie.)
  const std::vector<double> dense = {0.0, 0.375, 0.625, 0.875, 1.0};
  EXPECT_EQ(AssociateByTimestamp({0.5, 1.0}, dense, 0.2), (Pairs{{0, 1}, {1, 4}}));
  // Unsorted stamps take the brute-force path and agree.
  EXPECT_EQ(AssociateByTimestamp(reference, {0.33, 0.101}, 0.05), (Pairs{{3, 0}, {1, 1}}));
  EXPECT_EQ(AssociateByTimestamp(reference, {0.5}, 0.2).size(), 1u);
  EXPECT_THROW(AssociateByTimestamp(reference, {5.0, 5.1}), InputError);
}

}  // namespace
}  // namespace planeloc
