#include "planeloc/tracking/ba_worker.h"

#include <chrono>
#include <exception>

namespace planeloc {

void SolveBaJob(const StereoCamera& camera, const WindowBaOptions& options, BaJob& job,
                const CreaseChecker* creases) {
  const auto start = std::chrono::steady_clock::now();
  try {
    job.result = SolveWindowBa(camera, job.problem, options);
  } catch (const std::exception&) {
    job.result = WindowBaResult{};  // usable = false: the tracker keeps the map as it is
  }
  job.milliseconds =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  if (!creases) return;
  for (CreaseCheckJob& check : job.crease_checks) {
    check.result = creases->Compute(check.cam_from_world, camera, check.image);
    check.image.release();  // the tracker needs only the result
  }
}

BaWorker::BaWorker(const StereoCamera& camera, const WindowBaOptions& options,
                   const CreaseChecker* creases)
    : camera_(camera),
      options_(options),
      creases_(creases),
      thread_([this](std::stop_token stop) { Run(stop); }) {}

BaWorker::~BaWorker() {
  thread_.request_stop();
  wake_.notify_all();
}

bool BaWorker::Idle() {
  std::lock_guard lock(mutex_);
  return !pending_ && !running_ && !finished_;
}

bool BaWorker::Submit(BaJob job) {
  {
    std::lock_guard lock(mutex_);
    if (pending_ || running_ || finished_) return false;
    pending_ = std::move(job);
  }
  wake_.notify_all();
  return true;
}

std::optional<BaJob> BaWorker::TakeResult() {
  std::lock_guard lock(mutex_);
  std::optional<BaJob> result = std::move(finished_);
  finished_.reset();
  return result;
}

std::optional<BaJob> BaWorker::WaitResult() {
  std::unique_lock lock(mutex_);
  done_.wait(lock, [this] { return !pending_ && !running_; });
  std::optional<BaJob> result = std::move(finished_);
  finished_.reset();
  return result;
}

void BaWorker::Run(std::stop_token stop) {
  while (true) {
    BaJob job;
    {
      std::unique_lock lock(mutex_);
      if (!wake_.wait(lock, stop, [this] { return pending_.has_value(); })) return;
      job = std::move(*pending_);
      pending_.reset();
      running_ = true;
    }
    SolveBaJob(camera_, options_, job, creases_);
    {
      std::lock_guard lock(mutex_);
      finished_ = std::move(job);  // empty before: Submit refuses while a result waits
      running_ = false;
    }
    done_.notify_all();
  }
}

}  // namespace planeloc
