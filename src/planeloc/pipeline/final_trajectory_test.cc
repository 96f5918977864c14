#include "planeloc/pipeline/final_trajectory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace planeloc {
namespace {

Rigid3d At(double x, double y, double z) {
  return Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(x, y, z));
}

FrameStats Frame(int id, const char* map_lock, std::optional<int> keyframe_id = std::nullopt) {
  FrameStats stats;
  stats.frame = id;
  stats.map_lock = map_lock;
  stats.keyframe = keyframe_id.has_value();
  stats.keyframe_id = keyframe_id;
  return stats;
}

// Frames 1 m apart along z, frame i at z = i.
std::vector<Rigid3d> AlongZ(int frames) {
  std::vector<Rigid3d> poses;
  for (int i = 0; i < frames; ++i) poses.push_back(At(0, 0, i));
  return poses;
}

void ExpectPositions(const std::vector<Rigid3d>& poses,
                     const std::vector<Eigen::Vector3d>& expected) {
  ASSERT_EQ(poses.size(), expected.size());
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_NEAR((poses[i].translation - expected[i]).norm(), 0, 1e-12) << "frame " << i;
  }
}

TEST(FinalTrajectoryTest, FramesBeforeALockTakeTheCorrectionsThatCameAfterThem) {
  // Frames 0-1 searching, 2-3 after a partial lock (+1 m x), 4-5 after the full lock (+2 m y);
  // frame 5 also saw a re-registration (+3 m z), which corrects drift: no earlier frame takes it.
  const std::vector<Rigid3d> tracked = AlongZ(6);
  const std::vector<FrameStats> stats = {Frame(0, "searching", 0), Frame(1, "searching"),
                                         Frame(2, "partial", 1),   Frame(3, "partial"),
                                         Frame(4, "locked", 2),    Frame(5, "locked")};
  const std::vector<LockEvent> events = {{2, MapLock::kPartial, At(1, 0, 0), 0, false},
                                         {4, MapLock::kLocked, At(0, 2, 0), 0, false},
                                         {5, MapLock::kLocked, At(0, 0, 3), 0, true}};
  const std::vector<Rigid3d> final_poses = ReexpressBeforeLock(tracked, stats, events);
  ExpectPositions(final_poses, {{1, 2, 0}, {1, 2, 1}, {0, 2, 2}, {0, 2, 3}, {0, 0, 4}, {0, 0, 5}});
}

TEST(FinalTrajectoryTest, ARotationTurnsTheEarlierFramesWithTheMap) {
  // The lock turns the map 90 degrees about the vertical (y) through the map origin: a camera 1 m
  // along x, facing z, is then 1 m along -z facing x.
  const Rigid3d turn(
      Eigen::Quaterniond(Eigen::AngleAxisd(std::numbers::pi / 2, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d::Zero());
  const std::vector<Rigid3d> final_poses = ReexpressBeforeLock(
      {At(1, 0, 0), At(0, 0, 0)}, {Frame(0, "searching", 0), Frame(1, "locked")},
      {{1, MapLock::kLocked, turn, 0, false}});
  ExpectPositions(final_poses, {{0, 0, -1}, {0, 0, 0}});
  EXPECT_NEAR(
      (final_poses[0].RotationMatrix() * Eigen::Vector3d::UnitZ() - Eigen::Vector3d::UnitX())
          .norm(),
      0, 1e-12);
}

TEST(FinalTrajectoryTest, ALockOfALaterSegmentAndFramesLockedBeforeStay) {
  // Locked over frames 0-1; frame 2 lost (no state recorded: still locked); frame 3 restarts a
  // segment at keyframe 5 that searches and locks at frame 5.
  const std::vector<Rigid3d> tracked = AlongZ(6);
  const std::vector<FrameStats> stats = {Frame(0, "locked", 0), Frame(1, "locked", 4),
                                         Frame(2, ""),          Frame(3, "searching", 5),
                                         Frame(4, "searching"), Frame(5, "locked", 6)};
  const std::vector<Rigid3d> final_poses =
      ReexpressBeforeLock(tracked, stats, {{5, MapLock::kLocked, At(1, 0, 0), 5, false}});
  ExpectPositions(final_poses, {{0, 0, 0}, {0, 0, 1}, {0, 0, 2}, {1, 0, 3}, {1, 0, 4}, {0, 0, 5}});
}

TEST(FinalTrajectoryTest, ALockAtTheEndOfTheRunReachesEveryUnlockedFrame) {
  // Tracker::Finish applies a late registration after the last frame: its event names frame 2.
  const std::vector<Rigid3d> final_poses = ReexpressBeforeLock(
      {At(0, 0, 0), At(0, 0, 1)}, {Frame(0, "searching", 0), Frame(1, "partial")},
      {{2, MapLock::kLocked, At(0, 1, 0), 0, false}});
  ExpectPositions(final_poses, {{0, 1, 0}, {0, 1, 1}});
}

}  // namespace
}  // namespace planeloc
