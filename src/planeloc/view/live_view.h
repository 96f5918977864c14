// The live view of `planeloc run --view`: a small HTTP server that serves one page showing the
// run while it goes on, in the look of `planeloc report` (eval/html_page_kit.h):
//   GET /            the page: three.js, the plane map and the run so far, inlined
//   GET /events      Server-Sent Events, one JSON object per update (at most max_rate per second):
//                    the poses added since the client's last event, the lock state, fps and
//                    per-stage times, disabled planes, what the run learned about the planes
//                    (with --map-update, once a second), the current image's number
//   GET /frame.jpg   the current camera image (view/frame_drawing.h), JPEG
//   GET /settle?ms=  answers after `ms` (at most 10 s): a page given ?settle=N delays its load
//                    event by it, so that a headless browser's screenshot shows pushed updates
// and nothing else (404). It listens on loopback unless told otherwise.
//
// Decoupling: the tracking thread's calls (RunObserver) only copy a pose and a few numbers under
// a mutex, and a frame's image reference and keypoints at most max_rate times per second. The
// image is drawn and encoded on the view's own thread, and each browser is served on a thread
// of the server: a slow or absent browser never slows the run.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/pipeline/run_observer.h"

namespace planeloc::view {

struct LiveViewOptions {
  std::string host = "127.0.0.1";
  // std::nullopt: the first free port. A given port that is taken is an InputError naming it.
  std::optional<int> port;
  std::filesystem::path three_js_dir = "/usr/share/javascript/three";
  double max_rate = 10.0;  // updates per second pushed to each browser
  // Ground-truth positions per frame (the run's world frame): the trajectory is coloured by its
  // position error when given.
  std::vector<Eigen::Vector3d> gt_positions;
  std::string title = "planeloc live";
};

class LiveView final : public RunObserver {
 public:
  // Binds and starts serving. Throws InputError for an address that cannot be bound (naming it
  // and the fix) and for a missing three.js.
  static std::shared_ptr<LiveView> Start(const LiveViewOptions& options);
  ~LiveView() override;
  LiveView(const LiveView&) = delete;
  LiveView& operator=(const LiveView&) = delete;

  // "http://HOST:PORT/".
  std::string url() const;
  int port() const;
  // Ends every event stream and stops the server (also done by the destructor).
  void Stop();
  // Updates pushed so far (the view's own counter; for tests and the log).
  long updates() const;

  void OnStart(const StereoCamera& camera, int frames, const PlaneMap* plane_map) override;
  void OnFrame(const FrameStats& stats, const Rigid3d& world_from_cam) override;
  bool WantsFrameView() const override;
  bool WantsPlaneUpdates() const override;
  void OnFrameView(TrackedFrameView view) override;
  void OnFinish(const RunSummary& summary) override;

 private:
  struct Impl;
  explicit LiveView(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace planeloc::view
