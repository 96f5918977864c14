// planeloc_node: localizes a rectified stereo camera in a plane map, live in ROS 1.
//
// Subscribes (remap them): left/image_rect, right/image_rect (sensor_msgs/Image, mono8/rgb8/bgr8,
// paired by exact header stamp), left/camera_info, right/camera_info (rectified: P with the
// baseline; ros/ros_conversions.h). Publishes in the node's namespace: odometry
// (nav_msgs/Odometry), path (nav_msgs/Path), planes (visualization_msgs/MarkerArray, latched),
// status (std_msgs/String: "<tracking|lost|relocalized> map_lock=<...> points=N"), and the TF
// ~map_frame -> ~camera_frame. Parameters: ~planes, ~settings, ~init_pose ("12 numbers",
// row-major world_from_cam), ~init_sigma ("S_XY S_Z S_YAW_DEG"), ~deterministic, ~map_frame,
// ~camera_frame, ~queue_size. apps/ros/launch/planeloc.launch starts it.
//
// C++17 (ROS 1 messages are not C++20); the planeloc side is node_localizer.h.
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/exact_time.h>
#include <message_filters/synchronizer.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>
#include <tf2_ros/transform_broadcaster.h>
#include <visualization_msgs/MarkerArray.h>

#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "node_localizer.h"
#include "planeloc/ros/ros_conversions.h"
#include "planeloc/util/allocator.h"
#include "planeloc/util/error.h"

namespace planeloc::node {
namespace {

// "a b c ..." -> exactly N numbers; false otherwise.
template <std::size_t N>
bool ParseNumbers(const std::string& text, std::array<double, N>* out) {
  std::istringstream in(text);
  for (double& v : *out) {
    if (!(in >> v)) return false;
  }
  std::string rest;
  return !(in >> rest);
}

class PlanelocNode {
 public:
  PlanelocNode(::ros::NodeHandle& nh, ::ros::NodeHandle& pnh) : nh_(nh) {
    std::string init_pose, init_sigma;
    pnh.param<std::string>("planes", config_.planes_path, "");
    pnh.param<std::string>("settings", config_.settings_path, "");
    pnh.param<std::string>("init_pose", init_pose, "1 0 0 0 0 1 0 0 0 0 1 0");
    pnh.param<std::string>("init_sigma", init_sigma, "0 0 0");
    pnh.param<bool>("deterministic", config_.deterministic, false);
    pnh.param<std::string>("map_frame", map_frame_, "map");
    pnh.param<std::string>("camera_frame", camera_frame_, "camera");
    int queue = 10;
    pnh.param<int>("queue_size", queue, 10);
    CheckInput(ParseNumbers(init_pose, &config_.initial_pose), "~init_pose", 0,
               "expected 12 numbers (row-major 3x4 world_from_cam), got \"" + init_pose + "\"",
               "e.g. _init_pose:=\"1 0 0 0 0 1 0 0 0 0 1 0\"");
    CheckInput(ParseNumbers(init_sigma, &config_.init_sigma), "~init_sigma", 0,
               "expected 3 numbers \"S_XY S_Z S_YAW_DEG\", got \"" + init_sigma + "\"",
               "e.g. _init_sigma:=\"2 0.5 5\" or \"0 0 0\" (exact start)");

    odometry_pub_ = pnh.advertise<nav_msgs::Odometry>("odometry", 100);
    path_pub_ = pnh.advertise<nav_msgs::Path>("path", 10);
    status_pub_ = pnh.advertise<std_msgs::String>("status", 100);
    planes_pub_ = pnh.advertise<visualization_msgs::MarkerArray>("planes", 1, /*latch=*/true);
    if (!config_.planes_path.empty()) PublishPlanes();

    left_info_sub_ = nh.subscribe("left/camera_info", 10, &PlanelocNode::LeftInfo, this);
    right_info_sub_ = nh.subscribe("right/camera_info", 10, &PlanelocNode::RightInfo, this);
    left_sub_.subscribe(nh, "left/image_rect", queue);
    right_sub_.subscribe(nh, "right/image_rect", queue);
    sync_.emplace(Policy(queue), left_sub_, right_sub_);
    sync_->registerCallback(&PlanelocNode::Images, this);
    path_.header.frame_id = map_frame_;
    ROS_INFO("planeloc_node: waiting for stereo images on %s and %s", left_sub_.getTopic().c_str(),
             right_sub_.getTopic().c_str());
  }

  void Finish() {
    if (localizer_) localizer_->Finish();
  }

 private:
  using Policy = message_filters::sync_policies::ExactTime<sensor_msgs::Image, sensor_msgs::Image>;

  void LeftInfo(const sensor_msgs::CameraInfo::ConstPtr& info) { left_info_ = *info; }
  void RightInfo(const sensor_msgs::CameraInfo::ConstPtr& info) { right_info_ = *info; }

  void Images(const sensor_msgs::Image::ConstPtr& left, const sensor_msgs::Image::ConstPtr& right) {
    if (!localizer_ && !Start()) return;
    const NodeFrame frame = localizer_->Track(ros::GreyImage(*left, left_sub_.getTopic()),
                                              ros::GreyImage(*right, right_sub_.getTopic()),
                                              left->header.stamp.toSec());
    Publish(frame, left->header.stamp);
  }

  // The localizer, once both camera infos arrived; false (frame dropped) before.
  bool Start() {
    if (!left_info_ || !right_info_) {
      ROS_WARN_THROTTLE(5, "planeloc_node: no camera info yet on %s / %s: images dropped",
                        nh_.resolveName("left/camera_info").c_str(),
                        nh_.resolveName("right/camera_info").c_str());
      return false;
    }
    const StereoCamera camera =
        ros::StereoCameraFromInfo(*left_info_, *right_info_, nh_.resolveName("left/camera_info"),
                                  nh_.resolveName("right/camera_info"));
    NodeCamera c{camera.fx,       camera.fy,    camera.cx,    camera.cy,
                 camera.baseline, camera.width, camera.height};
    localizer_ = std::make_unique<NodeLocalizer>(config_, c);
    ROS_INFO("planeloc_node: tracking (fx %.3f, baseline %.4f m, %dx%d, plane map %s)", c.fx,
             c.baseline, c.width, c.height,
             config_.planes_path.empty() ? "none" : config_.planes_path.c_str());
    return true;
  }

  void Publish(const NodeFrame& frame, const ::ros::Time& stamp) {
    geometry_msgs::Pose pose;
    pose.position.x = frame.translation[0];
    pose.position.y = frame.translation[1];
    pose.position.z = frame.translation[2];
    pose.orientation.x = frame.rotation[0];
    pose.orientation.y = frame.rotation[1];
    pose.orientation.z = frame.rotation[2];
    pose.orientation.w = frame.rotation[3];

    nav_msgs::Odometry odometry;
    odometry.header.stamp = stamp;
    odometry.header.frame_id = map_frame_;
    odometry.child_frame_id = camera_frame_;
    odometry.pose.pose = pose;
    odometry_pub_.publish(odometry);

    geometry_msgs::TransformStamped transform;
    transform.header = odometry.header;
    transform.child_frame_id = camera_frame_;
    transform.transform.translation.x = pose.position.x;
    transform.transform.translation.y = pose.position.y;
    transform.transform.translation.z = pose.position.z;
    transform.transform.rotation = pose.orientation;
    tf_.sendTransform(transform);

    geometry_msgs::PoseStamped stamped;
    stamped.header = odometry.header;
    stamped.pose = pose;
    path_.header.stamp = stamp;
    path_.poses.push_back(stamped);
    path_pub_.publish(path_);

    std_msgs::String status;
    status.data = frame.state + " map_lock=" + (frame.map_lock.empty() ? "none" : frame.map_lock) +
                  " points=" + std::to_string(frame.tracked_points) +
                  (frame.keyframe ? " keyframe" : "");
    status_pub_.publish(status);
  }

  void PublishPlanes() {
    visualization_msgs::MarkerArray markers;
    for (const NodePlane& plane : ReadPlaneOutlines(config_.planes_path)) {
      visualization_msgs::Marker marker;
      marker.header.frame_id = map_frame_;
      marker.ns = "planes";
      marker.id = plane.id;
      marker.type = visualization_msgs::Marker::LINE_STRIP;
      marker.action = visualization_msgs::Marker::ADD;
      marker.pose.orientation.w = 1.0;
      marker.scale.x = 0.05;  // line width, metres
      marker.color.r = 0.2f;
      marker.color.g = 0.6f;
      marker.color.b = 1.0f;
      marker.color.a = 1.0f;
      for (const auto& p : plane.outline) {
        geometry_msgs::Point point;
        point.x = p[0];
        point.y = p[1];
        point.z = p[2];
        marker.points.push_back(point);
      }
      markers.markers.push_back(marker);
    }
    planes_pub_.publish(markers);
    ROS_INFO("planeloc_node: %zu planes of %s on %s (latched)", markers.markers.size(),
             config_.planes_path.c_str(), planes_pub_.getTopic().c_str());
  }

  ::ros::NodeHandle nh_;
  NodeConfig config_;
  std::string map_frame_, camera_frame_;
  ::ros::Publisher odometry_pub_, path_pub_, status_pub_, planes_pub_;
  ::ros::Subscriber left_info_sub_, right_info_sub_;
  message_filters::Subscriber<sensor_msgs::Image> left_sub_, right_sub_;
  std::optional<message_filters::Synchronizer<Policy>> sync_;
  tf2_ros::TransformBroadcaster tf_;
  std::optional<sensor_msgs::CameraInfo> left_info_, right_info_;
  std::unique_ptr<NodeLocalizer> localizer_;
  nav_msgs::Path path_;
};

}  // namespace
}  // namespace planeloc::node

int main(int argc, char** argv) {
  planeloc::KeepFreedMemoryForReuse();
  ::ros::init(argc, argv, "planeloc_node");
  ::ros::NodeHandle nh, pnh("~");
  try {
    planeloc::node::PlanelocNode node(nh, pnh);
    ::ros::spin();
    node.Finish();
  } catch (const planeloc::InputError& e) {
    // Bad parameters, plane map, settings or camera info: one message, exit 2 (as the CLI).
    ROS_FATAL("planeloc_node: %s", e.what());
    return 2;
  } catch (const planeloc::OptionsError& e) {
    ROS_FATAL("planeloc_node: %s", e.what());
    return 2;
  }
  return 0;
}
