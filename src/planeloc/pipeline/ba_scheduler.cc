#include "planeloc/pipeline/ba_scheduler.h"

#include <utility>

namespace planeloc {

BaScheduler::BaScheduler(std::function<void(BaJob&)> solve, int max_lag_frames)
    : worker_(std::move(solve)), max_lag_frames_(max_lag_frames) {}

bool BaScheduler::Idle() { return !deferred_keyframe_id_ && worker_.Idle(); }

BaScheduler::Admission BaScheduler::Admit(int keyframe_id) {
  if (Idle()) return Admission::kSubmitNow;
  const bool superseding = deferred_keyframe_id_.has_value();
  deferred_keyframe_id_ = keyframe_id;
  return superseding ? Admission::kDeferredSuperseding : Admission::kDeferred;
}

std::optional<int> BaScheduler::TakeDeferredWhenIdle() {
  if (!deferred_keyframe_id_ || !worker_.Idle()) return std::nullopt;
  return std::exchange(deferred_keyframe_id_, std::nullopt);
}

bool BaScheduler::Submit(BaJob job, int frame) {
  job.correction_epoch = correction_epoch_;
  if (!worker_.Submit(std::move(job))) return false;
  submitted_frame_ = frame;
  return true;
}

bool BaScheduler::Overdue(int frame) const {
  return submitted_frame_ && max_lag_frames_ > 0 && frame - *submitted_frame_ >= max_lag_frames_;
}

std::optional<BaJob> BaScheduler::TakeResult(bool wait) {
  std::optional<BaJob> job = wait ? worker_.WaitResult() : worker_.TakeResult();
  if (job || wait) submitted_frame_.reset();
  return job;
}

}  // namespace planeloc
