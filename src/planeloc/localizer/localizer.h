// planeloc's public API for the common case: localize a rectified stereo camera in a LiDAR plane
// map, one frame at a time.
//
//   planeloc::PlaneMap map = planeloc::OpenPlaneMap("planes.json");
//   planeloc::LocalizerOptions options;
//   options.tracker = planeloc::ReadTrackerOptions("settings.yaml");  // optional
//   options.world_from_cam_initial = first_pose;                      // in the map's frame
//   options.start_prior = {2.0, 0.5, 5.0};  // GNSS-like start; {} = exact
//   planeloc::Localizer localizer(camera, options, std::move(map));
//   for (each rectified grey stereo pair) {
//     const planeloc::LocalizedFrame f = localizer.Track(left, right, seconds);
//     use(f.world_from_cam, f.state, f.map_lock);
//   }
//   localizer.Finish();
//
// With the same images, options and deterministic = true the poses equal `planeloc run
// --deterministic` bit for bit (both drive the same Tracker). Errors: InputError for bad input
// (a plane map that does not parse, images of the wrong size or type), OptionsError for options
// out of range (util/error.h).
#pragma once

#include <filesystem>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <string>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/pipeline/frame_stats.h"
#include "planeloc/pipeline/settings.h"
#include "planeloc/prior/map_lock_options.h"

namespace planeloc {

// The pipeline behind the localizer (pipeline/tracker.h, for its sparse map, BA counts and lock
// events); not needed to localize.
class Tracker;
struct TrackResult;

struct LocalizerOptions {
  // ORB, stereo, BA, plane association and map-lock tunables (defaults: `planeloc run`'s).
  TrackerOptions tracker;
  // Pose of the first frame, in the plane map's frame (the frame of the returned poses).
  Rigid3d world_from_cam_initial;
  // How well world_from_cam_initial is known (metres, metres, degrees); exact by default. Unless
  // exact, the localizer first registers its stereo structure to the plane map (map lock).
  StartPrior start_prior;
  // Local BA in line on the caller's thread: bit-identical runs (sets tracker.deterministic).
  bool deterministic = false;
  // Throws OptionsError naming the field.
  void Check() const;
};

// One tracked frame.
struct LocalizedFrame {
  int frame = 0;           // 0-based index of the frame in the calls to Track/Skip
  double timestamp = 0;    // seconds, as given
  Rigid3d world_from_cam;  // in the plane map's frame (the initial pose's frame before a lock)
  TrackingState state = TrackingState::kTracking;
  std::string map_lock;  // "searching" | "partial" | "locked"; "" without a plane map
  bool keyframe = false;
  int tracked_points = 0;
  FrameStats stats;  // everything `planeloc run --stats` writes for the frame
  // Tracked (or relocalized) and, with a plane map, locked to it.
  bool Localized() const {
    return state != TrackingState::kLost && !stats.skipped &&
           (map_lock.empty() || map_lock == "locked");
  }
};

// Reads a plane map (planes.json of `planeloc map planes`, or a simulator's planes_gt.json).
// Throws InputError naming the file.
PlaneMap OpenPlaneMap(const std::filesystem::path& path);
// Tracker options from a settings file (ORB-SLAM2/ORB-SLAM3 stereo YAML and/or planeloc keys;
// docs/tracking.md); warnings and ignored keys are logged. The file's camera, if any, is not used
// here: pass the camera to the Localizer. Throws InputError naming the file, line and key.
TrackerOptions ReadTrackerOptions(const std::filesystem::path& settings);

class Localizer {
 public:
  // `camera`: the rectified stereo camera of the frames. Without a plane map the localizer is
  // stereo visual odometry in the frame of options.world_from_cam_initial.
  Localizer(const StereoCamera& camera, const LocalizerOptions& options,
            std::optional<PlaneMap> plane_map = std::nullopt);
  ~Localizer();
  Localizer(const Localizer&) = delete;
  Localizer& operator=(const Localizer&) = delete;

  // A rectified stereo pair: CV_8UC1 (or CV_8UC3 BGR, converted to grey) of the camera's size.
  // `timestamp` in seconds, increasing.
  LocalizedFrame Track(const cv::Mat& left, const cv::Mat& right, double timestamp);
  // A frame without usable images: the motion model's pose.
  LocalizedFrame Skip(double timestamp);
  // Waits for the running local BA (threaded mode); call after the last frame.
  void Finish();

  int frames() const { return frames_; }
  const StereoCamera& camera() const { return camera_; }
  const TrackerOptions& options() const;
  // The plane map (nullptr without one).
  const PlaneMap* plane_map() const { return plane_map_ ? plane_map_.get() : nullptr; }
  // The tracker behind it, for everything else (sparse map, BA counts, map-lock events).
  const Tracker& tracker() const { return *tracker_; }

 private:
  LocalizedFrame Result(const TrackResult& result, double timestamp);

  StereoCamera camera_;
  std::unique_ptr<PlaneMap> plane_map_;  // owned, at a fixed address: the tracker points to it
  std::unique_ptr<Tracker> tracker_;
  int frames_ = 0;
};

}  // namespace planeloc
