#include "node_localizer.h"

#include <fmt/format.h>

#include <optional>

#include "planeloc/localizer/localizer.h"
#include "planeloc/pipeline/run_sequence.h"

namespace planeloc::node {

std::vector<NodePlane> ReadPlaneOutlines(const std::string& planes_path) {
  std::vector<NodePlane> planes;
  for (const MapPlane& plane : OpenPlaneMap(planes_path).planes) {
    NodePlane outline;
    outline.id = plane.id;
    for (const Eigen::Vector3d& p : plane.polygon) outline.outline.push_back({p.x(), p.y(), p.z()});
    if (!outline.outline.empty()) outline.outline.push_back(outline.outline.front());  // closed
    planes.push_back(std::move(outline));
  }
  return planes;
}

struct NodeLocalizer::Impl {
  std::optional<Localizer> localizer;
};

NodeLocalizer::NodeLocalizer(const NodeConfig& config, const NodeCamera& camera)
    : impl_(std::make_unique<Impl>()) {
  StereoCamera stereo;
  stereo.fx = camera.fx;
  stereo.fy = camera.fy;
  stereo.cx = camera.cx;
  stereo.cy = camera.cy;
  stereo.baseline = camera.baseline;
  stereo.width = camera.width;
  stereo.height = camera.height;
  LocalizerOptions options;
  if (!config.settings_path.empty()) options.tracker = ReadTrackerOptions(config.settings_path);
  std::string pose;
  for (const double v : config.initial_pose) pose += fmt::format("{:.17g} ", v);
  options.world_from_cam_initial = ParsePose12(pose);
  options.start_prior.sigma_horizontal = config.init_sigma[0];
  options.start_prior.sigma_vertical = config.init_sigma[1];
  options.start_prior.sigma_yaw_deg = config.init_sigma[2];
  options.deterministic = config.deterministic;
  std::optional<PlaneMap> map;
  if (!config.planes_path.empty()) map = OpenPlaneMap(config.planes_path);
  impl_->localizer.emplace(stereo, options, std::move(map));
}

NodeLocalizer::~NodeLocalizer() = default;

NodeFrame NodeLocalizer::Track(const cv::Mat& left, const cv::Mat& right, double stamp) {
  const LocalizedFrame frame = impl_->localizer->Track(left, right, stamp);
  NodeFrame out;
  const Eigen::Vector3d& t = frame.world_from_cam.translation;
  const Eigen::Quaterniond& q = frame.world_from_cam.rotation;
  out.translation = {t.x(), t.y(), t.z()};
  out.rotation = {q.x(), q.y(), q.z(), q.w()};
  out.state = TrackingStateName(frame.state);
  out.map_lock = frame.map_lock;
  out.keyframe = frame.keyframe;
  out.localized = frame.Localized();
  out.tracked_points = frame.tracked_points;
  return out;
}

void NodeLocalizer::Finish() { impl_->localizer->Finish(); }

}  // namespace planeloc::node
