// When each keyframe's local BA runs in threaded mode, and which results may be applied.
//
// One BA at a time on a JobWorker. A keyframe inserted while one runs (or while its result waits
// to be applied) is deferred until the worker is idle; only the newest deferred keyframe is kept,
// an older one is superseded (its neighbourhood is in the newer window). A result solved before a
// map-frame correction (a lock, a consensus move) is stale: applying it would undo the
// correction. A BA still on the worker max_lag_frames after it was submitted is waited for, so
// the map never runs far ahead of its optimization.
#pragma once

#include <functional>
#include <optional>

#include "planeloc/pipeline/ba_job.h"
#include "planeloc/pipeline/job_worker.h"

namespace planeloc {

class BaScheduler {
 public:
  // `solve` runs on the worker thread (SolveBaJob with the run's camera and options).
  // `max_lag_frames` <= 0: never wait for a running BA.
  BaScheduler(std::function<void(BaJob&)> solve, int max_lag_frames);

  // No BA queued, running, waiting to be taken or deferred (ORB-SLAM2's AcceptKeyFrames).
  bool Idle();

  enum class Admission { kSubmitNow, kDeferred, kDeferredSuperseding };
  // A new keyframe. kSubmitNow when Idle(): build its window and Submit it. Otherwise it is
  // deferred, replacing a keyframe already deferred (kDeferredSuperseding).
  Admission Admit(int keyframe_id);
  // The deferred keyframe, if any.
  std::optional<int> deferred() const { return deferred_keyframe_id_; }
  // The deferred keyframe, handed out (and forgotten) once the worker is idle.
  std::optional<int> TakeDeferredWhenIdle();

  // Hands the job to the worker, stamped with the current correction epoch. `frame`: the frame
  // being tracked, for the lag bound. False when the worker refuses it (it was not idle).
  bool Submit(BaJob job, int frame);
  // True when the BA on the worker was submitted max_lag_frames or more before `frame`.
  bool Overdue(int frame) const;
  // The finished job, if any; with `wait`, after the running one finishes (the lag bound, the end
  // of the run). Either way the submission no longer counts for the lag bound.
  std::optional<BaJob> TakeResult(bool wait);

  // A map-frame correction was applied: every job built before it is stale.
  void OnCorrection() { ++correction_epoch_; }
  // True when `job` was built after the last correction.
  bool Current(const BaJob& job) const { return job.correction_epoch == correction_epoch_; }

 private:
  JobWorker<BaJob> worker_;
  int max_lag_frames_;
  std::optional<int> deferred_keyframe_id_;
  std::optional<int> submitted_frame_;  // frame at which the BA now on the worker was submitted
  int correction_epoch_ = 0;
};

}  // namespace planeloc
