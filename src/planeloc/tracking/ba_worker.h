// Runs local bundle adjustments on one owned worker thread. The tracker hands over a copy of the
// window (a WindowProblem, plain numbers keyed by id) and later takes the result back and applies
// it by id; the map itself is never shared, so there is no map mutex. One job at a time: while
// a job is queued, runs, or its result waits to be taken, new submissions are refused, so that
// the next window is always built from a map that holds the previous result (the tracker defers
// the keyframe's BA until then, see tracker.h).
#pragma once

#include <condition_variable>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>
#include <stop_token>
#include <thread>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/optim/window_ba.h"
#include "planeloc/tracking/crease_check.h"
#include "planeloc/tracking/local_mapping.h"

namespace planeloc {

// The LSD crease check of one keyframe (crease_check.h), run on the worker with the BA job that
// follows its keyframe, so that the frame path does not pay for it.
struct CreaseCheckJob {
  int keyframe_id = 0;
  Rigid3d cam_from_world;  // the keyframe's pose when it was inserted
  cv::Mat image;           // its left image at the check's pyramid level (owned copy)
  std::optional<KeyframeCreaseCheck> result;
};

struct BaJob {
  int keyframe_id = 0;  // keyframe whose insertion triggered the BA
  // Crease checks of the keyframes inserted since the last job (this one's included).
  std::vector<CreaseCheckJob> crease_checks;
  WindowProblem problem;
  // Version stamps of the window when it was built, and the tracker's map-frame correction count
  // then: a result solved before a correction is dropped, and one that finds a keyframe or
  // point moved since the snapshot leaves it as it is.
  WindowSnapshot snapshot;
  int correction_epoch = 0;
  WindowBaResult result;
  double milliseconds = 0;  // solve time
};

// Solves one job in the calling thread (the deterministic path; also used by the worker); runs
// its crease checks with `creases` when that is given.
void SolveBaJob(const StereoCamera& camera, const WindowBaOptions& options, BaJob& job,
                const CreaseChecker* creases = nullptr);

class BaWorker {
 public:
  // `creases` (may be null) must outlive the worker; the worker only calls its const Compute.
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
  bool running_ = false;
  std::jthread thread_;  // last member: started after the state above exists
};

}  // namespace planeloc
