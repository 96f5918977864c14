// The threaded BA's schedule with a solver the test releases by hand: deferral and superseding,
// the lag bound, and a result solved before a map correction marked stale.
#include "planeloc/pipeline/ba_scheduler.h"

#include <gtest/gtest.h>

#include <semaphore>

namespace planeloc {
namespace {

// A solver that blocks until the test releases it, and marks the job solved.
struct HeldSolver {
  std::counting_semaphore<8> release{0};
  void Solve(BaJob& job) {
    release.acquire();
    job.result.usable = true;
  }
};

BaJob JobFor(int keyframe_id) {
  BaJob job;
  job.keyframe_id = keyframe_id;
  return job;
}

TEST(BaSchedulerTest, DefersTheNewestKeyframeWhileABaRuns) {
  HeldSolver solver;
  BaScheduler scheduler([&solver](BaJob& job) { solver.Solve(job); }, /*max_lag_frames=*/3);
  ASSERT_TRUE(scheduler.Idle());
  ASSERT_EQ(scheduler.Admit(1), BaScheduler::Admission::kSubmitNow);
  ASSERT_TRUE(scheduler.Submit(JobFor(1), /*frame=*/10));
  EXPECT_FALSE(scheduler.Idle());
  EXPECT_FALSE(scheduler.Submit(JobFor(9), 10));  // one BA at a time

  EXPECT_EQ(scheduler.Admit(2), BaScheduler::Admission::kDeferred);
  EXPECT_EQ(scheduler.Admit(3), BaScheduler::Admission::kDeferredSuperseding);
  EXPECT_EQ(scheduler.deferred(), 3);
  EXPECT_FALSE(scheduler.TakeDeferredWhenIdle());  // the worker still runs keyframe 1

  // The lag bound counts frames since the submission.
  EXPECT_FALSE(scheduler.Overdue(12));
  EXPECT_TRUE(scheduler.Overdue(13));
  solver.release.release();
  std::optional<BaJob> done = scheduler.TakeResult(/*wait=*/true);
  ASSERT_TRUE(done);
  EXPECT_EQ(done->keyframe_id, 1);
  EXPECT_TRUE(done->result.usable);
  EXPECT_TRUE(scheduler.Current(*done));
  EXPECT_FALSE(scheduler.Overdue(100));  // nothing on the worker

  EXPECT_FALSE(scheduler.Idle());  // keyframe 3 still waits
  EXPECT_EQ(scheduler.TakeDeferredWhenIdle(), 3);
  EXPECT_FALSE(scheduler.deferred());
  EXPECT_TRUE(scheduler.Idle());
}

TEST(BaSchedulerTest, AResultSolvedBeforeACorrectionIsStale) {
  HeldSolver solver;
  BaScheduler scheduler([&solver](BaJob& job) { solver.Solve(job); }, /*max_lag_frames=*/0);
  ASSERT_TRUE(scheduler.Submit(JobFor(4), 20));
  EXPECT_FALSE(scheduler.Overdue(1000));  // no lag bound
  scheduler.OnCorrection();               // the map moved while keyframe 4's window was solved
  solver.release.release();
  std::optional<BaJob> stale = scheduler.TakeResult(/*wait=*/true);
  ASSERT_TRUE(stale);
  EXPECT_FALSE(scheduler.Current(*stale));

  // A job submitted after the correction is current.
  ASSERT_TRUE(scheduler.Submit(JobFor(5), 21));
  solver.release.release();
  std::optional<BaJob> fresh = scheduler.TakeResult(/*wait=*/true);
  ASSERT_TRUE(fresh);
  EXPECT_TRUE(scheduler.Current(*fresh));
  EXPECT_FALSE(scheduler.TakeResult(/*wait=*/false));
}

}  // namespace
}  // namespace planeloc
