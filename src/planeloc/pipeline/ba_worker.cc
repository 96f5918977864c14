#include "planeloc/pipeline/ba_worker.h"

#include <chrono>
#include <exception>

namespace planeloc {

void SolveBaJob(const StereoCamera& camera, const WindowBaOptions& options, BaJob& job) {
  const auto start = std::chrono::steady_clock::now();
  try {
    job.result = SolveWindowBa(camera, job.problem, options);
  } catch (const std::exception&) {
    job.result = WindowBaResult{};  // usable = false: the tracker keeps the map as it is
  }
  job.milliseconds =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
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

void BaWorker::SubmitCreaseCheck(CreaseCheckJob job) {
  if (!creases_) return;
  {
    std::lock_guard lock(mutex_);
    crease_pending_.push_back(std::move(job));
  }
  wake_.notify_all();
}

std::vector<CreaseCheckJob> BaWorker::TakeCreaseChecks() {
  std::lock_guard lock(mutex_);
  std::vector<CreaseCheckJob> checks = std::move(crease_finished_);
  crease_finished_.clear();
  return checks;
}

std::vector<CreaseCheckJob> BaWorker::WaitCreaseChecks() {
  std::unique_lock lock(mutex_);
  done_.wait(lock, [this] { return crease_pending_.empty() && !crease_running_; });
  std::vector<CreaseCheckJob> checks = std::move(crease_finished_);
  crease_finished_.clear();
  return checks;
}

void BaWorker::Run(std::stop_token stop) {
  while (true) {
    std::optional<BaJob> job;
    std::optional<CreaseCheckJob> check;
    {
      std::unique_lock lock(mutex_);
      if (!wake_.wait(lock, stop,
                      [this] { return pending_.has_value() || !crease_pending_.empty(); })) {
        return;
      }
      // A BA first: the tracker's next window waits for it; a crease check only feeds stats and
      // the (optional) gate.
      if (pending_) {
        job = std::move(pending_);
        pending_.reset();
        running_ = true;
      } else {
        check = std::move(crease_pending_.front());
        crease_pending_.pop_front();
        crease_running_ = true;
      }
    }
    if (job) {
      SolveBaJob(camera_, options_, *job);
    } else {
      check->result = creases_->Compute(check->cam_from_world, camera_, check->image);
      check->image.release();  // the tracker needs only the result
    }
    {
      std::lock_guard lock(mutex_);
      if (job) {
        finished_ = std::move(job);  // empty before: Submit refuses while a result waits
        running_ = false;
      } else {
        crease_finished_.push_back(std::move(*check));
        crease_running_ = false;
      }
    }
    done_.notify_all();
  }
}

}  // namespace planeloc
