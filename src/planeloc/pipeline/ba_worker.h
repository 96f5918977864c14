// Runs local bundle adjustments on one owned worker thread. The tracker hands over a copy of the
// window (a WindowProblem, plain numbers keyed by id) and later takes the result back and applies
// it by id; the map itself is never shared, so there is no map mutex. One job at a time: while
// a job is queued, runs, or its result waits to be taken, new submissions are refused, so that
// the next window is always built from a map that holds the previous result (the tracker defers
// the keyframe's BA until then, see tracker.h).
#pragma once

#include <condition_variable>
#include <deque>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <stop_token>
#include <thread>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/optim/window_ba.h"
#include "planeloc/prior/crease_check.h"
#include "planeloc/tracking/local_mapping.h"

namespace planeloc {

// The LSD crease check of one keyframe (crease_check.h), run on the worker when it has no BA to
// solve, so that neither the frame path nor the keyframes' BAs wait for it.
struct CreaseCheckJob {
  int keyframe_id = 0;
  Rigid3d cam_from_world;    // the keyframe's pose when it was inserted
  int correction_epoch = 0;  // the tracker's map-frame correction count then
  cv::Mat image;             // its left image at the check's pyramid level (owned copy)
  std::optional<KeyframeCreaseCheck> result;
};

struct BaJob {
  int keyframe_id = 0;  // keyframe whose insertion triggered the BA
  WindowProblem problem;
  // Version stamps of the window when it was built, and the tracker's map-frame correction count
  // then: a result solved before a correction is dropped, and one that finds a keyframe or
  // point moved since the snapshot leaves it as it is.
  WindowSnapshot snapshot;
  int correction_epoch = 0;
  WindowBaResult result;
  double milliseconds = 0;  // solve time
};

// Solves one job in the calling thread (the deterministic path; also used by the worker).
void SolveBaJob(const StereoCamera& camera, const WindowBaOptions& options, BaJob& job);

class BaWorker {
 public:
  // `creases` (may be null: no crease checks) must outlive the worker; the worker only calls its
  // const Compute.
  BaWorker(const StereoCamera& camera, const WindowBaOptions& options,
           const CreaseChecker* creases = nullptr);
  ~BaWorker();  // stops and joins; a running solve finishes first
  BaWorker(const BaWorker&) = delete;
  BaWorker& operator=(const BaWorker&) = delete;

  // True when no job is pending or running and no result waits to be taken.
  bool Idle();
  // Queues a job; false (job refused) unless Idle().
  bool Submit(BaJob job);
  // The finished job, if any (non-blocking).
  std::optional<BaJob> TakeResult();
  // Blocks until no job is pending or running, then returns its result if any.
  std::optional<BaJob> WaitResult();

  // Crease checks: queued without limit and run in order whenever no BA job is pending (a BA
  // submitted meanwhile waits for at most the check that is running). Needs `creases`.
  void SubmitCreaseCheck(CreaseCheckJob job);
  // The finished checks (non-blocking), in submission order.
  std::vector<CreaseCheckJob> TakeCreaseChecks();
  // Blocks until every queued check has run, then returns the finished ones.
  std::vector<CreaseCheckJob> WaitCreaseChecks();

 private:
  void Run(std::stop_token stop);

  StereoCamera camera_;
  WindowBaOptions options_;
  const CreaseChecker* creases_;
  std::mutex mutex_;
  std::condition_variable_any wake_;
  std::condition_variable done_;
  std::optional<BaJob> pending_;
  std::optional<BaJob> finished_;
  bool running_ = false;  // a BA job
  std::deque<CreaseCheckJob> crease_pending_;
  std::vector<CreaseCheckJob> crease_finished_;
  bool crease_running_ = false;
  std::jthread thread_;  // last member: started after the state above exists
};

}  // namespace planeloc
