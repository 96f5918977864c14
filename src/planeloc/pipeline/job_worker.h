// One owned worker thread that runs jobs of one kind, one at a time (the local BA, the map
// lock's registrations). The caller hands over a self-contained job (a copy of what it needs,
// never a reference into the tracker's map) and later takes it back with its result; the
// algorithm itself holds no thread and no lock. While a job is queued, runs, or its result waits
// to be taken, new submissions are refused: the caller decides whether to defer or drop its job.
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <stop_token>
#include <thread>
#include <utility>

namespace planeloc {

template <typename Job>
class JobWorker {
 public:
  // `run` fills in the job's result; it must not throw (report failure in the job instead).
  explicit JobWorker(std::function<void(Job&)> run)
      : run_(std::move(run)), thread_([this](std::stop_token stop) { Loop(stop); }) {}
  ~JobWorker() {  // stops and joins; a running job finishes first
    thread_.request_stop();
    wake_.notify_all();
  }
  JobWorker(const JobWorker&) = delete;
  JobWorker& operator=(const JobWorker&) = delete;

  // True when no job is queued or running and no result waits to be taken.
  bool Idle() {
    std::lock_guard lock(mutex_);
    return !pending_ && !running_ && !finished_;
  }
  // Queues a job; false (job refused) unless Idle().
  bool Submit(Job job) {
    {
      std::lock_guard lock(mutex_);
      if (pending_ || running_ || finished_) return false;
      pending_ = std::move(job);
    }
    wake_.notify_all();
    return true;
  }
  // The finished job, if any (non-blocking).
  std::optional<Job> TakeResult() {
    std::lock_guard lock(mutex_);
    return std::exchange(finished_, std::nullopt);
  }
  // Blocks until no job is queued or running, then returns its result if any.
  std::optional<Job> WaitResult() {
    std::unique_lock lock(mutex_);
    done_.wait(lock, [this] { return !pending_ && !running_; });
    return std::exchange(finished_, std::nullopt);
  }

 private:
  void Loop(std::stop_token stop) {
    while (true) {
      Job job;
      {
        std::unique_lock lock(mutex_);
        if (!wake_.wait(lock, stop, [this] { return pending_.has_value(); })) return;
        job = std::move(*pending_);
        pending_.reset();
        running_ = true;
      }
      run_(job);
      {
        std::lock_guard lock(mutex_);
        finished_ = std::move(job);  // empty before: Submit refuses while a result waits
        running_ = false;
      }
      done_.notify_all();
    }
  }

  std::function<void(Job&)> run_;
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::condition_variable done_;
  std::optional<Job> pending_;
  std::optional<Job> finished_;
  bool running_ = false;
  std::jthread thread_;  // last member: started after the state above exists
};

}  // namespace planeloc
