// The map lock end to end on the simulator's `tiny` preset (one straight street): a run started
// off its map pose registers itself to the plane map; the same run with the registration off
// keeps the start error. Also: the lock survives a blackout.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/map/map_builder.h"
#include "planeloc/map/map_planes.h"
#include "planeloc/pipeline/run_sequence.h"
#include "planeloc/pipeline/tiny_drive_for_test.h"
#include "planeloc/pipeline/tracker.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;

class MapLockSimTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>("planeloc-map-lock-sim");
    // The other tracking tests use the preset's default seed.
    result_ = &testing::SharedTinySim(kSeed);
    planes_ = &testing::SharedTinyPlanes(kSeed);
  }
  static void TearDownTestSuite() { dir_.reset(); }

  // The first GT pose moved 1.2 m sideways (x), 0.3 m up and 0.6 m ahead, and turned 3 deg.
  static Rigid3d CoarseStart() {
    const Rigid3d& truth = result_->world_from_cam.front();
    const Eigen::Matrix3d yaw(Eigen::AngleAxisd(3.0 * kDegree, Eigen::Vector3d::UnitY()));
    return Rigid3d(Eigen::Quaterniond(yaw * truth.RotationMatrix()),
                   truth.translation + Eigen::Vector3d(1.2, -0.3, 0.6));
  }

  static RunSummary Run(const std::string& name, const StartPrior& prior) {
    RunOptions run;
    run.sequence = result_->sequence_dir;
    run.trajectory_path = dir_->path() / (name + ".txt");
    run.final_trajectory_path = dir_->path() / (name + ".final.txt");
    run.deterministic = true;
    run.show_progress = false;
    run.world_from_cam_initial = CoarseStart();
    run.planes_path = testing::SharedTinyPlanesPath(kSeed);
    run.start_prior = prior;
    return RunSequence(run);
  }

  // Lateral (x) and vertical (y) position errors: the street runs along z.
  static double CrossTrackError(const Rigid3d& estimate, int frame) {
    const Eigen::Vector3d d = estimate.translation - result_->world_from_cam[frame].translation;
    return std::hypot(d.x(), d.y());
  }

  static std::unique_ptr<TempDir> dir_;
  static constexpr int kSeed = 5;
  static const sim::SimResult* result_;
  static const PlaneMap* planes_;
};

std::unique_ptr<TempDir> MapLockSimTest::dir_;
const sim::SimResult* MapLockSimTest::result_ = nullptr;
const PlaneMap* MapLockSimTest::planes_ = nullptr;

TEST_F(MapLockSimTest, CoarseStartLocksOntoThePlaneMap) {
  StartPrior gnss;
  gnss.sigma_horizontal = 2.0;
  gnss.sigma_vertical = 0.5;
  gnss.sigma_yaw_deg = 5.0;
  const RunSummary locked = Run("coarse", gnss);
  StartPrior exact;  // registration off: the start error is never corrected
  const RunSummary unlocked = Run("coarse_exact_prior", exact);
  ASSERT_EQ(locked.frames, result_->frames);
  ASSERT_FALSE(locked.lock_events.empty());
  EXPECT_NE(locked.final_map_lock, "searching");
  const int lock_frame = locked.lock_events.front().frame;
  // Measured (seed 5, 22c0ed5+merges, `planeloc_tracking_test --gtest_filter=MapLock*`): first
  // lock at frame 37 of 60, worst cross-track error after it 0.140 m; without registration the
  // mean cross-track error is 3.76 m (the 3 deg heading error grows it along the street).
  double locked_worst = 0, unlocked_mean = 0;
  for (int i = lock_frame; i < locked.frames; ++i) {
    locked_worst = std::max(locked_worst, CrossTrackError(locked.world_from_cam[i], i));
    unlocked_mean += CrossTrackError(unlocked.world_from_cam[i], i);
  }
  unlocked_mean /= locked.frames - lock_frame;
  std::cout << "lock at frame " << lock_frame << ", cross-track error after it: worst "
            << locked_worst << " m; without registration: mean " << unlocked_mean << " m\n";
  EXPECT_LT(lock_frame, 50);
  EXPECT_LT(locked_worst, 0.25);
  EXPECT_GT(unlocked_mean, 0.8);
  // The heading error is gone too.
  const Rigid3d& last = locked.world_from_cam.back();
  EXPECT_LT(RotationAngle(last.rotation, result_->world_from_cam.back().rotation), 0.5 * kDegree);

  // --out-final: the frames before the first lock, written in the prior's frame (1.2 m and 3 deg
  // off at the start), are re-expressed in the map frame by the corrections that followed them.
  // The street leaves along-track free (the lock is partial): the cross-track error counts.
  // Measured (seed 5, `planeloc_pipeline_test --gtest_filter=MapLockSimTest.CoarseStart*`): worst
  // cross-track error before the lock 0.148 m in --out-final (as after it), 3.17 m as written.
  const Trajectory final_poses = ReadKittiTrajectory(dir_->path() / "coarse.final.txt");
  ASSERT_EQ(final_poses.world_from_cam.size(), locked.world_from_cam.size());
  double written_before = 0, final_before = 0;
  for (int i = 0; i < lock_frame; ++i) {
    written_before = std::max(written_before, CrossTrackError(locked.world_from_cam[i], i));
    final_before = std::max(final_before, CrossTrackError(final_poses.world_from_cam[i], i));
  }
  std::cout << "before the lock: worst cross-track error written " << written_before
            << " m, in --out-final " << final_before << " m\n";
  EXPECT_GT(written_before, 0.8);
  EXPECT_LT(final_before, 0.25);
  // From the last lock event on, the frames are as written.
  for (int i = locked.lock_events.back().frame; i < locked.frames; ++i) {
    EXPECT_NEAR(
        (final_poses.world_from_cam[i].translation - locked.world_from_cam[i].translation).norm(),
        0, 1e-6)
        << "frame " << i;
  }
}

// A plane map that cannot fix the pose (the road alone: heading, lateral and along-track are
// free): the run never claims a full lock and leaves the start's lateral and heading error as
// they are, i.e. it stays visual odometry in the prior's frame instead of fabricating a lock.
TEST_F(MapLockSimTest, RoadOnlyMapNeverLocks) {
  PlaneMap road = *planes_;
  std::erase_if(road.planes, [](const MapPlane& plane) { return plane.kind != "ground"; });
  ASSERT_FALSE(road.planes.empty());
  ASSERT_LT(road.planes.size(), planes_->planes.size());
  WritePlaneMap(dir_->path() / "road.json", road);
  RunOptions run;
  run.sequence = result_->sequence_dir;
  run.trajectory_path = dir_->path() / "road.txt";
  run.deterministic = true;
  run.show_progress = false;
  run.world_from_cam_initial = CoarseStart();
  run.planes_path = dir_->path() / "road.json";
  run.start_prior.sigma_horizontal = 2.0;
  run.start_prior.sigma_vertical = 0.5;
  run.start_prior.sigma_yaw_deg = 5.0;
  const RunSummary summary = RunSequence(run);
  ASSERT_EQ(summary.frames, result_->frames);
  EXPECT_NE(summary.final_map_lock, "locked");
  for (const LockEvent& event : summary.lock_events) EXPECT_NE(event.lock, MapLock::kLocked);
  double mean_lateral = 0;
  const int from = result_->frames / 2;
  for (int i = from; i < summary.frames; ++i) {
    mean_lateral += std::abs(summary.world_from_cam[i].translation.x() -
                             result_->world_from_cam[i].translation.x());
  }
  mean_lateral /= summary.frames - from;
  std::cout << "road-only map: final lock " << summary.final_map_lock << ", "
            << summary.lock_events.size()
            << " lock events, mean lateral error over the second half " << mean_lateral << " m\n";
  // The start is 1.2 m and 3 deg off sideways; the coarse-start test above measures 3.76 m of
  // cross-track error without registration. A lateral "correction" the road cannot give would
  // bring this below the start's 1.2 m. Measured (seed 5, db3db3b+,
  // `planeloc_tracking_test --gtest_filter=MapLock*RoadOnly*`): still searching at the end, no
  // lock event, 3.57 m.
  EXPECT_GT(mean_lateral, 1.0);
}

// Recovery in the map after an outage: 10 black frames, or 10 frames that never arrive (1 s at
// 10 Hz). The run starts at the exact map pose so that the outage is the only error source.
TEST_F(MapLockSimTest, PoseAfterAnOutageIsBackInTheMapWithinTwentyFrames) {
  const KittiSequence sequence = KittiSequence::Open(result_->sequence_dir);
  for (const bool black : {true, false}) {
    TrackerOptions options;
    options.deterministic = true;
    Tracker tracker(sequence.camera(), options, result_->world_from_cam.front(), planes_);
    constexpr int kOutageStart = 15, kOutageEnd = 25;  // frames [15, 25)
    double worst_after = 0;
    const int frames = std::min<int>(result_->frames, kOutageEnd + 20);
    for (int i = 0; i < frames; ++i) {
      const bool outage = i >= kOutageStart && i < kOutageEnd;
      TrackResult r;
      if (outage && !black) {
        r = tracker.SkipFrame(sequence.timestamp(i));
      } else {
        StereoPair pair = sequence.LoadStereoPair(i);
        if (outage) {
          pair.left.setTo(0);
          pair.right.setTo(0);
        }
        r = tracker.Track(pair.left, pair.right, sequence.timestamp(i));
      }
      if (i >= kOutageEnd) {
        worst_after = std::max(
            worst_after,
            (r.world_from_cam.translation - result_->world_from_cam[i].translation).norm());
      }
    }
    std::cout << (black ? "blackout" : "frame gap")
              << ": worst error in the 20 frames after: " << worst_after << " m\n";
    // Measured (seed 5, `planeloc_tracking_test --gtest_filter=MapLock*Outage*`): 0.236 m for
    // both (the tracker re-initializes at frame 25 in both cases); 0.73 m before the prediction
    // across an outage kept only the heading rate. The bound is the (0.3 m).
    EXPECT_LT(worst_after, 0.3) << (black ? "blackout" : "frame gap");
  }
}

// A run started at the first GT pose moved 0.3 m sideways but declared exact: the mean lateral
// error over the last 10 frames, and the tracker's corrections of it.
struct SidewaysRun {
  double final_lateral_error = 0;  // metres
  int recorrections = 0;           // map-lock re-registrations applied
  int consensus_corrections = 0;   // map moves by the planes' consensus
};
SidewaysRun RunFromSidewaysStart(const TrackerOptions& options, const sim::SimResult& result,
                                 const PlaneMap& planes) {
  const KittiSequence sequence = KittiSequence::Open(result.sequence_dir);
  const Rigid3d& truth = result.world_from_cam.front();
  const Rigid3d start(truth.rotation, truth.translation + Eigen::Vector3d(0.3, 0.0, 0.0));
  Tracker tracker(sequence.camera(), options, start, &planes);
  SidewaysRun run;
  int counted = 0;
  for (int i = 0; i < result.frames; ++i) {
    const StereoPair pair = sequence.LoadStereoPair(i);
    const TrackResult r = tracker.Track(pair.left, pair.right, sequence.timestamp(i));
    if (i >= result.frames - 10) {
      run.final_lateral_error +=
          std::abs(r.world_from_cam.translation.x() - result.world_from_cam[i].translation.x());
      ++counted;
    }
  }
  tracker.Finish();
  run.final_lateral_error /= counted;
  for (const LockEvent& event : tracker.lock_events()) run.recorrections += event.recorrection;
  run.consensus_corrections = tracker.consensus_corrections();
  return run;
}

// A start declared exact (--init-sigma "0 0 0") that is 0.3 m off sideways: beyond the
// association band (Planes.maxDistance 0.15 m) the window BA never pulls it back; the
// re-registration while locked does. Without it, the error stays.
TEST_F(MapLockSimTest, ReRegistrationCorrectsAnErrorBeyondTheAssociationBand) {
  SidewaysRun runs[2];
  // Every 4 keyframes: the tiny drive has only 15 keyframes (the default, 10, tries once, at
  // frame 37, where the lateral DoF is not yet constrained enough).
  for (const int every : {4, 0}) {
    TrackerOptions options;
    options.deterministic = true;
    options.map_lock.maintain_every_keyframes = every;
    options.planes.trajectory_consensus = false;  // the other way back (the test below)
    runs[every > 0 ? 0 : 1] = RunFromSidewaysStart(options, *result_, *planes_);
  }
  std::cout << "lateral error over the last 10 frames: with re-registration "
            << runs[0].final_lateral_error << " m (" << runs[0].recorrections
            << " re-corrections), without " << runs[1].final_lateral_error << " m\n";
  // Measured (seed 5, `planeloc_tracking_test --gtest_filter=MapLock*ReReg*`): one
  // re-correction at frame 46; lateral error over frames 50-59 0.040 m with it, 0.308 m without
  // (0.035 / 0.312 m at e9dba2c).
  EXPECT_GE(runs[0].recorrections, 1);
  EXPECT_EQ(runs[1].recorrections, 0);
  EXPECT_LT(runs[0].final_lateral_error, 0.08);
  EXPECT_GT(runs[1].final_lateral_error, 0.2);
}

// The same start, 0.3 m off sideways, with Planes.trajectoryConsensus instead of the
// re-registration: the facades on both sides of the street agree that the trajectory is 0.3 m
// off, and the tracker moves its map by it. Without, the error stays (the test above).
TEST_F(MapLockSimTest, PlaneConsensusCorrectsAnErrorBeyondTheAssociationBand) {
  SidewaysRun runs[2];
  for (const bool consensus : {true, false}) {
    TrackerOptions options;
    options.deterministic = true;
    options.planes.trajectory_consensus = consensus;
    runs[consensus ? 0 : 1] = RunFromSidewaysStart(options, *result_, *planes_);
  }
  std::cout << "lateral error over the last 10 frames: with the plane consensus "
            << runs[0].final_lateral_error << " m (" << runs[0].consensus_corrections
            << " map moves), without " << runs[1].final_lateral_error << " m\n";
  // Measured (seed 5, `planeloc_pipeline_test --gtest_filter=MapLock*Consensus*`, e9dba2c
  // defaults: 3 facades of 3 points): one map move; lateral error over frames 50-59 0.050 m with
  // it, 0.312 m without (0.059 m with 2 facades of 5 points). With point fusion on by default
  // and the bias test sparing facades whose peers share their bias (session 31): 2 map moves,
  // 0.016 m with it, 0.285 m without; before that sparing, fusion left 0 map moves and 0.285 m.
  EXPECT_GE(runs[0].consensus_corrections, 1);
  EXPECT_EQ(runs[1].consensus_corrections, 0);
  EXPECT_LT(runs[0].final_lateral_error, 0.1);
  EXPECT_GT(runs[1].final_lateral_error, 0.2);
}

// Issue 30: the default path (a GNSS-like prior) given the *exact* start must not end worse than
// the exact start itself. Tiny seed 3: a partial lock at frame 22 used to move the camera 0.71 m
// along the street, the direction the registration called unobserved, and the run ended at
// 0.53 m ATE against 0.052 m from the exact start.
class MapLockExactStartSimTest : public ::testing::Test {
 protected:
  // Plane mode on dir/planes.json with `prior`; visual odometry when `prior` is std::nullopt.
  static RunSummary Run(const std::filesystem::path& dir, const sim::SimResult& sim,
                        const std::string& name, const std::optional<StartPrior>& prior) {
    RunOptions run;
    run.sequence = sim.sequence_dir;
    run.trajectory_path = dir / (name + ".txt");
    run.deterministic = true;
    run.show_progress = false;
    run.world_from_cam_initial = sim.world_from_cam.front();
    if (prior) {
      run.planes_path = dir / "planes.json";
      run.start_prior = *prior;
    }
    return RunSequence(run);
  }
  static double Ate(const RunSummary& run, const sim::SimResult& sim) {
    double sum = 0;
    for (int i = 0; i < run.frames; ++i) {
      sum += (run.world_from_cam[i].translation - sim.world_from_cam[i].translation).squaredNorm();
    }
    return std::sqrt(sum / run.frames);
  }

  // Tiny seed `seed` and its own clean plane map, run with the default prior (GNSS-like) and with
  // the exact start, both from the exact pose of frame 0, and (`with_vo`) as visual odometry.
  struct ExactStartRuns {
    double ate_prior = 0, ate_exact = 0, ate_vo = 0;  // metres, every frame, no alignment
    bool locked = false;
  };
  // Tiny seed `seed` (rendered once per test process) with its own clean plane map written to
  // dir/planes.json.
  static const sim::SimResult& MakeTinyDrive(int seed, const std::filesystem::path& dir) {
    WritePlaneMap(dir / "planes.json", testing::SharedTinyPlanes(seed));
    return testing::SharedTinySim(seed);
  }
  // `planeloc run`'s default `--init-sigma "2 0.5 5"` (GNSS-like).
  static StartPrior DefaultPrior() {
    StartPrior gnss;
    gnss.sigma_horizontal = 2.0;
    gnss.sigma_vertical = 0.5;
    gnss.sigma_yaw_deg = 5.0;
    return gnss;
  }
  static ExactStartRuns RunTinySeed(int seed, bool with_vo) {
    TempDir dir("planeloc-map-lock-exact");
    const sim::SimResult& sim = MakeTinyDrive(seed, dir.path());
    const RunSummary with_prior = Run(dir.path(), sim, "prior", DefaultPrior());
    const RunSummary exact = Run(dir.path(), sim, "exact", StartPrior());
    EXPECT_EQ(with_prior.frames, sim.frames);
    ExactStartRuns runs;
    runs.locked = !with_prior.lock_events.empty();
    runs.ate_prior = Ate(with_prior, sim);
    runs.ate_exact = Ate(exact, sim);
    if (with_vo) runs.ate_vo = Ate(Run(dir.path(), sim, "vo", std::nullopt), sim);
    std::cout << "tiny seed " << seed << ", exact start: ATE with the default prior "
              << runs.ate_prior << " m, exact start " << runs.ate_exact << " m, VO " << runs.ate_vo
              << " m\n";
    return runs;
  }
};

TEST_F(MapLockExactStartSimTest, DefaultPriorFromTheExactStartIsNotWorseThanTheExactStart) {
  const ExactStartRuns runs = RunTinySeed(3, /*with_vo=*/false);
  ASSERT_TRUE(runs.locked);
  // Measured (`planeloc_pipeline_test --gtest_filter=MapLockExact*`, 2026-12-07, session 38):
  // 0.0435 m with the prior against 0.0466 m exact (VO 0.0592 m; `planeloc run` gives the same).
  // Before issue 30: 0.53 m.
  EXPECT_LT(runs.ate_prior, 0.10);
  EXPECT_LT(runs.ate_prior, 1.6 * runs.ate_exact);
}

// The window after the full lock frees the segment but keeps its oldest keyframe where the lock
// put it. With that keyframe free too, tiny seed 5's segment slid along the street after a lock
// that applied nothing, and the default path ended above visual odometry.
TEST_F(MapLockExactStartSimTest, DefaultPriorFromTheExactStartStaysBelowVisualOdometry) {
  const ExactStartRuns runs = RunTinySeed(5, /*with_vo=*/true);
  ASSERT_TRUE(runs.locked);
  // Measured (`planeloc_pipeline_test --gtest_filter=MapLockExact*`, 2026-12-07, session 38):
  // 0.0562 m with the prior, 0.0451 m exact (1.25x), VO 0.0594 m; with the oldest keyframe free
  // (`planeloc run --init-sigma "2 0.5 5" --deterministic` on the same drive) 0.0664 m, above VO
  // and 1.47x the exact start. The goal is 1.1x; this bound catches the slide.
  EXPECT_LT(runs.ate_prior, runs.ate_vo);
  EXPECT_LT(runs.ate_prior, 1.35 * runs.ate_exact);
}

// A partial lock also opens one window over the segment with no anchor, held by its oldest
// keyframe: the planes then hold lateral, height and heading, and pull the whole segment onto
// them instead of only its newest keyframes. Tiny seed 11 locks partially at frame 36 from the
// exact start with the default prior and never fully.
TEST_F(MapLockExactStartSimTest, ThePartialLockOpensOneWindowHeldByItsOldestKeyframe) {
  TempDir dir("planeloc-map-lock-partial");
  const sim::SimResult& sim = MakeTinyDrive(11, dir.path());
  const RunSummary run = Run(dir.path(), sim, "prior", DefaultPrior());
  ASSERT_FALSE(run.lock_events.empty());
  ASSERT_EQ(run.lock_events.front().lock, MapLock::kPartial);
  const int lock_frame = run.lock_events.front().frame;
  // The fixed keyframes of each applied BA, before and after the lock.
  std::vector<int> before, after;
  for (const FrameStats& frame : run.stats) {
    if (!frame.ba_fixed_keyframes) continue;
    (frame.frame > lock_frame ? after : before).push_back(*frame.ba_fixed_keyframes);
  }
  ASSERT_GE(after.size(), 2u);
  std::cout << "partial lock at frame " << lock_frame << "; fixed keyframes of the BAs before it:";
  for (const int n : before) std::cout << " " << n;
  std::cout << "; after it:";
  for (const int n : after) std::cout << " " << n;
  std::cout << "\n";
  // Measured (`planeloc_pipeline_test --gtest_filter=MapLockExact*`, 2026-12-07, session 39):
  // partial lock at frame 36; fixed keyframes of the BAs after it 1 2 3 4 5 6 (the last BA before
  // it 2); with the window after the full lock only (a8281eb) 2 2 3 4 5 6.
  EXPECT_EQ(after.front(), 1);
  EXPECT_GT(after[1], 1);
}

}  // namespace
}  // namespace planeloc
