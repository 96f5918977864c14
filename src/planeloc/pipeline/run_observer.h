// A watcher of a run (RunOptions::observer), e.g. the live view of `planeloc run --view`.
// RunSequence calls it on the tracking thread, in frame order. A call must return quickly and
// never wait for anything slow (a browser, a socket, a disk): the observer copies what it needs
// and does its own work on its own threads.
#pragma once

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/pipeline/frame_stats.h"
#include "planeloc/pipeline/tracker.h"

namespace planeloc {

struct RunSummary;

class RunObserver {
 public:
  virtual ~RunObserver() = default;
  // Before the first frame: the effective camera, the frame count to be tracked, and the plane
  // map (nullptr: visual odometry). The map outlives the run's calls.
  virtual void OnStart(const StereoCamera& camera, int frames, const PlaneMap* plane_map) = 0;
  // After every frame, once its pose is written.
  virtual void OnFrame(const FrameStats& stats, const Rigid3d& world_from_cam) = 0;
  // Asked after OnFrame: whether to describe the frame (OnFrameView). Describing costs the
  // tracking thread a plane lookup per tracked point, so an observer asks at its own rate.
  virtual bool WantsFrameView() const = 0;
  // Asked with it: whether the view should also carry what the run has learned about the
  // planes so far (TrackedFrameView::plane_updates; a fit per plane, so at a lower rate).
  virtual bool WantsPlaneUpdates() const = 0;
  virtual void OnFrameView(TrackedFrameView view) = 0;
  // After the last frame, with the run's summary (before the report folder is written).
  virtual void OnFinish(const RunSummary& summary) = 0;
};

}  // namespace planeloc
