// The local BA as a job for a JobWorker: the tracker hands over a copy of the window (a
// WindowProblem, plain numbers keyed by id) and later applies the result by id; the map itself is
// never shared, so there is no map mutex. The worker refuses a job while the previous one is not
// taken, so the next window is always built from a map that holds the previous result (the
// tracker defers the keyframe's BA until then, see tracker.h).
#pragma once

#include "planeloc/geometry/camera.h"
#include "planeloc/optim/window_ba.h"
#include "planeloc/pipeline/job_worker.h"
#include "planeloc/tracking/local_mapping.h"

namespace planeloc {

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

// Solves one job in the calling thread (the deterministic path; also what the worker runs). A
// solver that throws leaves an unusable result: the tracker keeps the map as it is.
void SolveBaJob(const StereoCamera& camera, const WindowBaOptions& options, BaJob& job);

using BaWorker = JobWorker<BaJob>;

}  // namespace planeloc
