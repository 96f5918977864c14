#include "planeloc/view/live_view.h"

#include <fmt/format.h>
#include <httplib.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <deque>
#include <limits>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "planeloc/eval/html_page_kit.h"
#include "planeloc/pipeline/run_sequence.h"
#include "planeloc/util/error.h"
#include "planeloc/view/frame_drawing.h"

namespace planeloc::view {
namespace {

#include "planeloc/view/live_view_page.inc"

using Clock = std::chrono::steady_clock;
using nlohmann::json;

// Lock state codes of the page (LOCK_COLORS): no plane map, searching, partial, locked.
int LockCode(const std::string& lock) {
  if (lock == "searching") return 1;
  if (lock == "partial") return 2;
  if (lock == "locked") return 3;
  return 0;
}

struct PoseRecord {
  Eigen::Vector3f position;
  int lock = 0;
  float error = std::numeric_limits<float>::quiet_NaN();  // metres; NaN without GT
  bool keyframe = false;
};

double Round(double value, double scale) {
  return std::isfinite(value) ? std::round(value * scale) / scale : 0.0;
}

// Exponential moving average of a per-frame time (the page shows it, not one noisy frame).
void Smooth(double value, double& average, bool first) {
  average = first ? value : 0.9 * average + 0.1 * value;
}

struct ClientState {
  long version = 0;
  std::size_t poses_sent = 0;
};

}  // namespace

struct LiveView::Impl {
  LiveViewOptions options;
  std::string three_js;  // <script> elements
  httplib::Server server;
  std::thread server_thread;
  std::atomic<bool> listen_returned = false;  // server_thread's listen_after_bind() returned
  std::thread publisher_thread;
  int port = 0;

  mutable std::mutex mutex;
  std::condition_variable changed;  // version bumped, or stopping
  std::condition_variable wake_publisher;
  bool stopping = false;
  long version = 0;    // bumped by the publisher, at most options.max_rate times per second
  bool dirty = false;  // frames since the last version
  long updates = 0;    // events written to browsers

  // Set by OnStart.
  StereoCamera camera;
  int total_frames = 0;
  std::optional<PlaneMap> plane_map;
  json planes = json::array();
  Eigen::Vector3d up = Eigen::Vector3d::Zero();

  std::vector<PoseRecord> poses;
  FrameStats last_stats;
  Rigid3d last_pose;
  double ms_extract = 0, ms_track = 0, ms_local_map = 0, ms_ba = 0;  // smoothed
  int keyframes = 0, lost = 0;
  std::vector<int> disabled_planes;
  std::vector<std::pair<int, std::string>> lock_changes;  // frame, new lock state
  std::deque<Clock::time_point> frame_times;              // of the last second

  std::optional<TrackedFrameView> pending_view;  // for the publisher to draw
  Rigid3d pending_pose;
  std::atomic<std::int64_t> next_view_ns{0};     // steady clock: when the next frame view is wanted
  std::atomic<std::int64_t> next_updates_ns{0};  // and the next plane updates
  // Plane id -> what the run learned about it (unseen planes left out).
  std::map<int, std::string> plane_states;

  std::shared_ptr<const std::string> jpeg;  // the current camera image
  long image_number = 0;
  int image_frame = -1;

  bool finished = false;
  json summary;

  Clock::duration Period() const {
    return std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(1.0 / std::max(options.max_rate, 0.1)));
  }

  // What changed since pose `from` (under the mutex).
  json Event(std::size_t from) const {
    json event;
    event["version"] = version;
    event["from"] = from;
    json list = json::array();
    for (std::size_t i = from; i < poses.size(); ++i) {
      const PoseRecord& p = poses[i];
      list.push_back({Round(p.position.x(), 1e3), Round(p.position.y(), 1e3),
                      Round(p.position.z(), 1e3), p.lock,
                      std::isfinite(p.error) ? json(Round(p.error, 1e4)) : json(nullptr),
                      p.keyframe ? 1 : 0});
    }
    event["poses"] = std::move(list);
    event["frames"] = total_frames;
    event["frame"] = poses.empty() ? -1 : last_stats.frame;
    event["state"] = TrackingStateName(last_stats.state);
    event["lock"] = last_stats.map_lock;
    const auto now = Clock::now();
    double fps = 0;
    if (finished && summary.contains("seconds") && summary["seconds"].get<double>() > 0) {
      fps = summary["frames"].get<double>() / summary["seconds"].get<double>();
    } else if (frame_times.size() > 1) {
      const double span =
          std::chrono::duration<double>(frame_times.back() - frame_times.front()).count();
      if (span > 0 && now - frame_times.back() < std::chrono::seconds(2)) {
        fps = (frame_times.size() - 1) / span;
      }
    }
    event["fps"] = Round(fps, 10);
    event["ms"] = {{"extract", Round(ms_extract, 100)},
                   {"track", Round(ms_track, 100)},
                   {"local_map", Round(ms_local_map, 100)},
                   {"ba", Round(ms_ba, 100)}};
    event["features"] = last_stats.features;
    event["tracked"] = last_stats.tracked_points;
    event["keyframes"] = keyframes;
    event["lost"] = lost;
    event["disabled"] = disabled_planes;
    json states = json::object();
    for (const auto& [id, state] : plane_states) states[std::to_string(id)] = state;
    event["plane_states"] = std::move(states);
    json changes = json::array();
    for (const auto& [frame, lock] : lock_changes) changes.push_back({frame, lock});
    event["lock_changes"] = std::move(changes);
    event["image"] = image_number;
    event["image_frame"] = image_frame;
    event["finished"] = finished;
    if (finished) event["summary"] = summary;
    return event;
  }

  std::string Page() const {
    json data;
    {
      std::lock_guard lock(mutex);
      data["title"] = options.title;
      data["up"] = {up.x(), up.y(), up.z()};
      data["planes"] = planes;
      data["gt"] = !options.gt_positions.empty();
      data["rate"] = options.max_rate;
      data["state"] = Event(0);
    }
    std::string page;
    page.reserve(three_js.size() + (1 << 16));
    page += PageKitHead();
    page += "<title>" + HtmlEscape(options.title) + "</title>\n";
    page += "<link rel=\"icon\" href=\"data:,\">\n";
    page += PageKitStyle();
    page += kLiveStyle;
    page += "</head>\n";
    page += kLiveBody;
    page += three_js;
    page += "<script type=\"application/json\" id=\"live-data\">" + JsonScriptSafe(data.dump()) +
            "</script>\n<script>\n";
    page += PageKitScript();
    page += kLiveScript;
    page += "</script>\n</body>\n</html>\n";
    return page;
  }

  void PublishLoop() {
    std::unique_lock lock(mutex);
    while (!stopping) {
      wake_publisher.wait_for(lock, Period(), [this] { return stopping; });
      if (stopping) break;
      bool publish = dirty;
      dirty = false;
      if (pending_view) {
        TrackedFrameView view = std::move(*pending_view);
        pending_view.reset();
        const Rigid3d pose = pending_pose;
        lock.unlock();
        // Drawn and encoded here, never on the tracking thread.
        const cv::Mat image =
            DrawTrackedFrame(view, camera, pose, plane_map ? &*plane_map : nullptr);
        std::shared_ptr<std::string> encoded;
        if (!image.empty()) {
          std::vector<uchar> bytes;
          if (cv::imencode(".jpg", image, bytes, {cv::IMWRITE_JPEG_QUALITY, 80})) {
            encoded = std::make_shared<std::string>(bytes.begin(), bytes.end());
          }
        }
        lock.lock();
        if (encoded) {
          jpeg = std::move(encoded);
          ++image_number;
          image_frame = view.frame;
          publish = true;
        }
      }
      if (publish) {
        ++version;
        changed.notify_all();
      }
    }
  }

  void Routes() {
    server.Get("/", [this](const httplib::Request&, httplib::Response& response) {
      response.set_header("Cache-Control", "no-store");
      response.set_content(Page(), "text/html; charset=utf-8");
    });
    server.Get("/frame.jpg", [this](const httplib::Request&, httplib::Response& response) {
      std::shared_ptr<const std::string> image;
      {
        std::lock_guard lock(mutex);
        image = jpeg;
      }
      response.set_header("Cache-Control", "no-store");
      if (!image) {
        response.status = 404;
        response.set_content("no frame yet", "text/plain");
        return;
      }
      response.set_content(*image, "image/jpeg");
    });
    server.Get("/settle", [this](const httplib::Request& request, httplib::Response& response) {
      int ms = 0;
      try {
        ms = std::clamp(std::stoi(request.get_param_value("ms")), 0, 10000);
      } catch (const std::exception&) {
        ms = 0;
      }
      {
        std::unique_lock lock(mutex);
        changed.wait_for(lock, std::chrono::milliseconds(ms), [this] { return stopping; });
      }
      response.set_header("Cache-Control", "no-store");
      response.set_content("", "text/plain");
    });
    server.Get("/events", [this](const httplib::Request&, httplib::Response& response) {
      response.set_header("Cache-Control", "no-store");
      auto client = std::make_shared<ClientState>();
      response.set_chunked_content_provider(
          "text/event-stream", [this, client](std::size_t, httplib::DataSink& sink) {
            std::string text;
            {
              std::unique_lock lock(mutex);
              changed.wait_for(lock, std::chrono::seconds(1),
                               [&] { return stopping || version != client->version; });
              if (stopping) {
                sink.done();
                return true;
              }
              if (version == client->version) {
                text = ": keep-alive\n\n";  // also finds a browser that went away
              } else {
                text = "data: " + Event(client->poses_sent).dump() + "\n\n";
                client->poses_sent = poses.size();
                client->version = version;
                ++updates;
              }
            }
            // A browser that went away fails the write: its stream ends, the run goes on.
            return sink.write(text.data(), text.size());
          });
    });
  }
};

LiveView::LiveView(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

LiveView::~LiveView() { Stop(); }

std::shared_ptr<LiveView> LiveView::Start(const LiveViewOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->options = options;
  impl->three_js = ThreeJsScripts(options.three_js_dir);
  const std::string address =
      options.port ? fmt::format("{}:{}", options.host, *options.port) : options.host;
  CheckInput(!options.port || (*options.port > 0 && *options.port < 65536), address, 0,
             "--view: the port must be in 1..65535",
             "e.g. --view 127.0.0.1:8080, or --view "
             "alone for a free port");
  // Idle keep-alive connections hold a server thread; one second keeps Stop() quick.
  impl->server.set_keep_alive_timeout(1);
  // cpp-httplib's default also sets SO_REUSEPORT, with which a second server silently shares a
  // port that is taken; SO_REUSEADDR alone still restarts at once on a port in TIME_WAIT.
  impl->server.set_socket_options([](int socket) {
    const int yes = 1;
    setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  impl->Routes();
  if (options.port) {
    CheckInput(impl->server.bind_to_port(options.host, *options.port), address, 0,
               "--view: cannot listen on this address (the port is taken, or the host is not "
               "an address of this machine)",
               "pass another port (--view 127.0.0.1:PORT), or --view alone to take a free one");
    impl->port = *options.port;
  } else {
    impl->port = impl->server.bind_to_any_port(options.host);
    CheckInput(impl->port > 0, address, 0,
               "--view: cannot listen on this host (not an address of this machine)",
               "pass a local address, e.g. --view 127.0.0.1 (the default)");
  }
  Impl* raw = impl.get();
  impl->server_thread = std::thread([raw] {
    raw->server.listen_after_bind();
    raw->listen_returned = true;
  });
  // cpp-httplib's stop() does nothing until listen_after_bind() has marked the server running,
  // and the accept loop it starts after that never ends: a view stopped right after Start() hung
  // in Stop()'s join (the `view` test, once under CI load, until ctest's 900 s timeout). So the
  // view exists only once its server runs.
  while (!impl->server.is_running() && !impl->listen_returned) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (!impl->server.is_running()) {
    impl->server_thread.join();
    CheckInput(false, address, 0, "--view: the server stopped as it started",
               "pass another address or port (--view 127.0.0.1:PORT)");
  }
  impl->publisher_thread = std::thread([raw] { raw->PublishLoop(); });
  return std::shared_ptr<LiveView>(new LiveView(std::move(impl)));
}

std::string LiveView::url() const {
  return fmt::format("http://{}:{}/", impl_->options.host, impl_->port);
}

int LiveView::port() const { return impl_->port; }

long LiveView::updates() const {
  std::lock_guard lock(impl_->mutex);
  return impl_->updates;
}

void LiveView::Stop() {
  {
    std::lock_guard lock(impl_->mutex);
    if (impl_->stopping && !impl_->server_thread.joinable()) return;
    impl_->stopping = true;
  }
  impl_->changed.notify_all();
  impl_->wake_publisher.notify_all();
  impl_->server.stop();
  if (impl_->server_thread.joinable()) impl_->server_thread.join();
  if (impl_->publisher_thread.joinable()) impl_->publisher_thread.join();
}

void LiveView::OnStart(const StereoCamera& camera, int frames, const PlaneMap* plane_map) {
  json planes = json::array();
  if (plane_map) {
    for (const MapPlane& plane : plane_map->planes) {
      if (plane.polygon.size() < 3) continue;
      json polygon = json::array();
      for (const Eigen::Vector3d& v : plane.polygon) {
        polygon.push_back({Round(v.x(), 1e3), Round(v.y(), 1e3), Round(v.z(), 1e3)});
      }
      const cv::Scalar bgr = PlaneColorBgr(plane.id);
      planes.push_back(
          {{"id", plane.id},
           {"kind", plane.kind},
           {"polygon", std::move(polygon)},
           {"color", fmt::format("#{:02x}{:02x}{:02x}", static_cast<int>(bgr[2]),
                                 static_cast<int>(bgr[1]), static_cast<int>(bgr[0]))}});
    }
  }
  std::lock_guard lock(impl_->mutex);
  impl_->camera = camera;
  impl_->total_frames = frames;
  if (plane_map) {
    impl_->plane_map = *plane_map;
    impl_->up = plane_map->frame.up;
  }
  impl_->planes = std::move(planes);
  impl_->dirty = true;
}

void LiveView::OnFrame(const FrameStats& stats, const Rigid3d& world_from_cam) {
  const auto now = Clock::now();
  std::lock_guard lock(impl_->mutex);
  Impl& s = *impl_;
  PoseRecord record;
  record.position = world_from_cam.translation.cast<float>();
  record.lock = LockCode(stats.map_lock);
  record.keyframe = stats.keyframe;
  const std::size_t index = s.poses.size();
  if (index < s.options.gt_positions.size()) {
    record.error =
        static_cast<float>((world_from_cam.translation - s.options.gt_positions[index]).norm());
  }
  // Without a map's up: the first camera's -y (image rows point down).
  if (s.up.isZero()) s.up = -(world_from_cam.rotation * Eigen::Vector3d::UnitY());
  const bool first = s.poses.empty();
  if (s.poses.empty() || s.last_stats.map_lock != stats.map_lock) {
    if (!stats.map_lock.empty()) s.lock_changes.emplace_back(stats.frame, stats.map_lock);
  }
  s.poses.push_back(record);
  s.last_stats = stats;
  s.last_pose = world_from_cam;
  Smooth(stats.ms_extract, s.ms_extract, first);
  Smooth(stats.ms_track, s.ms_track, first);
  Smooth(stats.ms_local_map, s.ms_local_map, first);
  Smooth(stats.ms_ba, s.ms_ba, first);
  if (stats.keyframe) ++s.keyframes;
  if (stats.state == TrackingState::kLost) ++s.lost;
  s.frame_times.push_back(now);
  while (s.frame_times.size() > 2 && now - s.frame_times.front() > std::chrono::seconds(1)) {
    s.frame_times.pop_front();
  }
  s.dirty = true;
}

bool LiveView::WantsFrameView() const {
  return Clock::now().time_since_epoch().count() >= impl_->next_view_ns.load();
}

bool LiveView::WantsPlaneUpdates() const {
  return Clock::now().time_since_epoch().count() >= impl_->next_updates_ns.load();
}

void LiveView::OnFrameView(TrackedFrameView view) {
  const auto now = Clock::now();
  impl_->next_view_ns.store((now + impl_->Period()).time_since_epoch().count());
  if (!view.plane_updates.empty()) {
    // A fit per plane on the tracking thread: once a second is plenty for a map that changes
    // over minutes.
    impl_->next_updates_ns.store((now + std::chrono::seconds(1)).time_since_epoch().count());
  }
  std::lock_guard lock(impl_->mutex);
  impl_->disabled_planes = view.disabled_planes;
  if (!view.plane_updates.empty()) {
    impl_->plane_states.clear();
    for (const PlaneUpdate& update : view.plane_updates) {
      if (update.status != PlaneUpdateStatus::kUnseen) {
        impl_->plane_states[update.id] = ToString(update.status);
      }
    }
  }
  impl_->pending_pose = impl_->last_pose;  // the pose the image was tracked at
  impl_->pending_view = std::move(view);
  impl_->dirty = true;
}

void LiveView::OnFinish(const RunSummary& summary) {
  json parsed = json::parse(summary.ToJson(), nullptr, false);
  std::lock_guard lock(impl_->mutex);
  impl_->finished = true;
  impl_->summary = parsed.is_discarded() ? json::object() : std::move(parsed);
  impl_->dirty = true;
}

}  // namespace planeloc::view
