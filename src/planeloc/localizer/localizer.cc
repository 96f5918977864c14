#include "planeloc/localizer/localizer.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <opencv2/imgproc.hpp>

#include "planeloc/pipeline/tracker.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// Grey, of the camera's size; `side` names the image in the error.
cv::Mat GreyImage(const cv::Mat& image, const StereoCamera& camera, const char* side) {
  CheckInput(!image.empty(), "", 0, fmt::format("the {} image is empty", side),
             "pass a decoded rectified image");
  CheckInput(image.cols == camera.width && image.rows == camera.height, "", 0,
             fmt::format("the {} image is {}x{}, the camera {}x{}", side, image.cols, image.rows,
                         camera.width, camera.height),
             "pass images of the calibrated size (rectified, not cropped or scaled)");
  CheckInput(image.depth() == CV_8U && (image.channels() == 1 || image.channels() == 3), "", 0,
             fmt::format("the {} image has {} channels of depth {}", side, image.channels(),
                         image.depth()),
             "pass 8-bit grey (CV_8UC1) or BGR (CV_8UC3) images");
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

}  // namespace

void LocalizerOptions::Check() const {
  tracker.Check();
  start_prior.Check();
  if (!world_from_cam_initial.translation.allFinite() ||
      !world_from_cam_initial.rotation.coeffs().allFinite()) {
    throw OptionsError("LocalizerOptions.world_from_cam_initial: not finite");
  }
}

PlaneMap OpenPlaneMap(const std::filesystem::path& path) { return ReadPlaneMap(path); }

TrackerOptions ReadTrackerOptions(const std::filesystem::path& settings) {
  SettingsFile file = LoadTrackerSettings(settings, TrackerOptions{});
  for (const auto& warning : file.warnings) spdlog::warn("{}: {}", settings.string(), warning);
  if (file.camera) {
    spdlog::info("{}: the camera keys are not used by the Localizer (it is given the camera)",
                 settings.string());
  }
  return file.options;
}

Localizer::Localizer(const StereoCamera& camera, const LocalizerOptions& options,
                     std::optional<PlaneMap> plane_map)
    : camera_(camera) {
  camera_.Check();
  LocalizerOptions effective = options;
  TrackerOptions& tracker = effective.tracker;
  // As `planeloc run`: the deterministic mode solves the local BA in line.
  if (effective.deterministic) tracker.deterministic = true;
  effective.Check();
  if (plane_map) plane_map_ = std::make_unique<PlaneMap>(std::move(*plane_map));
  tracker_ = std::make_unique<Tracker>(camera_, tracker, effective.world_from_cam_initial,
                                       plane_map_.get(), effective.start_prior);
}

Localizer::~Localizer() = default;

LocalizedFrame Localizer::Track(const cv::Mat& left, const cv::Mat& right, double timestamp) {
  const cv::Mat left_grey = GreyImage(left, camera_, "left");
  const cv::Mat right_grey = GreyImage(right, camera_, "right");
  return Result(tracker_->Track(left_grey, right_grey, timestamp), timestamp);
}

LocalizedFrame Localizer::Skip(double timestamp) {
  return Result(tracker_->SkipFrame(timestamp), timestamp);
}

void Localizer::Finish() { tracker_->Finish(); }

const TrackerOptions& Localizer::options() const { return tracker_->options(); }

LocalizedFrame Localizer::Result(const TrackResult& result, double timestamp) {
  LocalizedFrame frame;
  frame.frame = frames_++;
  frame.timestamp = timestamp;
  frame.world_from_cam = result.world_from_cam;
  frame.state = result.stats.state;
  frame.map_lock = result.stats.map_lock;
  frame.keyframe = result.stats.keyframe;
  frame.tracked_points = result.stats.tracked_points;
  frame.stats = result.stats;
  return frame;
}

}  // namespace planeloc
