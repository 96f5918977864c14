// The public Localizer against `planeloc run` (RunSequence) on the simulator's tiny preset, and
// its checks of the images it is given.
#include "planeloc/localizer/localizer.h"

#include <gtest/gtest.h>

#include <memory>

#include "planeloc/io/kitti_sequence.h"
#include "planeloc/pipeline/run_sequence.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

constexpr int kFrames = 15;

class LocalizerTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>("planeloc-localizer");
    sim::SimOptions options = sim::SimOptions::FromPreset("tiny");
    options.frames = kFrames;
    options.show_progress = false;
    result_ =
        std::make_unique<sim::SimResult>(sim::GenerateSequence(options, dir_->path() / "sim"));
  }
  static void TearDownTestSuite() {
    result_.reset();
    dir_.reset();
  }
  static std::unique_ptr<TempDir> dir_;
  static std::unique_ptr<sim::SimResult> result_;
};

std::unique_ptr<TempDir> LocalizerTest::dir_;
std::unique_ptr<sim::SimResult> LocalizerTest::result_;

// Same frames, same plane map, exact start, deterministic: the Localizer drives the same Tracker
// as `planeloc run`, so the poses are bit-identical.
TEST_F(LocalizerTest, DeterministicPosesEqualRunSequence) {
  RunOptions run;
  run.sequence = result_->sequence_dir;
  run.trajectory_path = dir_->path() / "run.txt";
  run.planes_path = result_->planes_path;
  run.deterministic = true;
  run.show_progress = false;
  const RunSummary summary = RunSequence(run);
  ASSERT_EQ(summary.world_from_cam.size(), static_cast<std::size_t>(kFrames));

  const KittiSequence sequence = KittiSequence::Open(result_->sequence_dir);
  LocalizerOptions options;
  options.deterministic = true;
  Localizer localizer(sequence.camera(), options, OpenPlaneMap(result_->planes_path));
  ASSERT_NE(localizer.plane_map(), nullptr);
  for (int i = 0; i < kFrames; ++i) {
    const StereoPair pair = sequence.LoadStereoPair(i);
    const LocalizedFrame frame = localizer.Track(pair.left, pair.right, sequence.timestamp(i));
    EXPECT_EQ(frame.frame, i);
    EXPECT_TRUE(frame.Localized()) << "frame " << i;
    // The Localizer reports the lock state the run's stats record for the frame.
    ASSERT_LT(static_cast<std::size_t>(i), summary.stats.size());
    EXPECT_EQ(frame.map_lock, summary.stats[i].map_lock) << i;
    EXPECT_FALSE(frame.map_lock.empty()) << i;  // a plane map is given
    EXPECT_EQ(frame.world_from_cam.translation, summary.world_from_cam[i].translation) << i;
    EXPECT_TRUE(frame.world_from_cam.rotation.coeffs().isApprox(
        summary.world_from_cam[i].rotation.coeffs(), 0.0))
        << i;
  }
  localizer.Finish();
  EXPECT_EQ(localizer.frames(), kFrames);
}

TEST_F(LocalizerTest, RejectsImagesOfAnotherSizeOrType) {
  const KittiSequence sequence = KittiSequence::Open(result_->sequence_dir);
  Localizer localizer(sequence.camera(), LocalizerOptions{});
  const StereoPair pair = sequence.LoadStereoPair(0);
  cv::Mat small;
  pair.left(cv::Rect(0, 0, 100, 100)).copyTo(small);
  EXPECT_THROW(localizer.Track(small, pair.right, 0.0), InputError);
  cv::Mat wide;
  pair.left.convertTo(wide, CV_16U);
  EXPECT_THROW(localizer.Track(wide, pair.right, 0.0), InputError);
  EXPECT_THROW(localizer.Track(cv::Mat(), pair.right, 0.0), InputError);
  EXPECT_EQ(localizer.frames(), 0);
}

TEST(LocalizerOptionsTest, CheckNamesTheField) {
  LocalizerOptions options;
  options.start_prior.sigma_horizontal = -1;
  EXPECT_THROW(options.Check(), OptionsError);
  LocalizerOptions threads;
  threads.tracker.num_threads = 0;
  EXPECT_THROW(threads.Check(), OptionsError);
}

}  // namespace
}  // namespace planeloc
