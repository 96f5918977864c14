// Test helper of planeloc_node (tests/ros_node_test.sh): plays the stereo frames of a bag written
// by `planeloc convert kitti-to-bag` at a fixed rate (the camera info once 1 s ahead, then per
// frame its camera info and two images, stamps as recorded) and records what the node publishes:
// the poses of ~odometry as KITTI lines, the count of latched plane markers and the last status.
//   planeloc_stereo_player BAG RATE_HZ NODE_NAMESPACE OUT_POSES TIMEOUT_S
// Exit 0 when one pose came back per frame, 1 otherwise. C++17 (ROS 1 messages).
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/String.h>
#include <visualization_msgs/MarkerArray.h>

#include <Eigen/Geometry>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace {

struct Frame {
  std::vector<std::pair<std::string, sensor_msgs::Image::ConstPtr>> images;
  std::vector<std::pair<std::string, sensor_msgs::CameraInfo::ConstPtr>> infos;
};

// Frames in record order (the converter records the four messages of a frame at one time).
std::map<ros::Time, Frame> ReadFrames(const std::string& bag_path) {
  std::map<ros::Time, Frame> frames;
  rosbag::Bag bag(bag_path, rosbag::bagmode::Read);
  for (const rosbag::MessageInstance& m : rosbag::View(bag)) {
    Frame& frame = frames[m.getTime()];
    if (auto image = m.instantiate<sensor_msgs::Image>())
      frame.images.emplace_back(m.getTopic(), image);
    if (auto info = m.instantiate<sensor_msgs::CameraInfo>())
      frame.infos.emplace_back(m.getTopic(), info);
  }
  return frames;
}

std::map<std::string, ros::Publisher> AdvertiseTopics(ros::NodeHandle& nh,
                                                      const std::map<ros::Time, Frame>& frames) {
  std::map<std::string, ros::Publisher> publishers;
  for (const auto& [time, frame] : frames) {
    for (const auto& [topic, image] : frame.images) {
      if (!publishers.count(topic))
        publishers[topic] = nh.advertise<sensor_msgs::Image>(topic, 100);
    }
    for (const auto& [topic, info] : frame.infos) {
      if (!publishers.count(topic))
        publishers[topic] = nh.advertise<sensor_msgs::CameraInfo>(topic, 100);
    }
  }
  return publishers;
}

// What the node published, kept by the subscriptions' callbacks.
struct Recording {
  std::vector<nav_msgs::Odometry> poses;
  std::size_t plane_markers = 0;
  std::string status;
};

void PlayFrames(const std::map<ros::Time, Frame>& frames,
                std::map<std::string, ros::Publisher>& publishers, double rate_hz) {
  // The camera info first, on its own: the node drops images until it has both (messages on
  // different topics may arrive in any order).
  for (const auto& [topic, info] : frames.begin()->second.infos) publishers[topic].publish(info);
  ros::WallDuration(1.0).sleep();
  ros::WallRate rate(rate_hz);
  for (const auto& [time, frame] : frames) {
    for (const auto& [topic, info] : frame.infos) publishers[topic].publish(info);
    for (const auto& [topic, image] : frame.images) publishers[topic].publish(image);
    ros::spinOnce();
    rate.sleep();
  }
}

// The poses as KITTI lines (world_from_cam, row-major 3x4); false when the file cannot be opened.
bool WriteKittiPoses(const char* path, const std::vector<nav_msgs::Odometry>& poses) {
  std::FILE* out = std::fopen(path, "w");
  if (!out) return false;
  for (const nav_msgs::Odometry& m : poses) {
    const auto& p = m.pose.pose;
    const Eigen::Matrix3d r =
        Eigen::Quaterniond(p.orientation.w, p.orientation.x, p.orientation.y, p.orientation.z)
            .toRotationMatrix();
    std::fprintf(out, "%.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e\n", r(0, 0),
                 r(0, 1), r(0, 2), p.position.x, r(1, 0), r(1, 1), r(1, 2), p.position.y, r(2, 0),
                 r(2, 1), r(2, 2), p.position.z);
  }
  std::fclose(out);
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: %s BAG RATE_HZ NODE_NAMESPACE OUT_POSES TIMEOUT_S\n", argv[0]);
    return 2;
  }
  ros::init(argc, argv, "planeloc_stereo_player", ros::init_options::AnonymousName);
  ros::NodeHandle nh;
  const double rate_hz = std::stod(argv[2]);
  const std::string node = argv[3];
  const double timeout = std::stod(argv[5]);

  const std::map<ros::Time, Frame> frames = ReadFrames(argv[1]);
  if (frames.empty()) {
    std::fprintf(stderr, "player: %s holds no message\n", argv[1]);
    return 1;
  }
  std::map<std::string, ros::Publisher> publishers = AdvertiseTopics(nh, frames);

  Recording recording;
  auto odometry_sub = nh.subscribe<nav_msgs::Odometry>(
      node + "/odometry", 1000,
      [&](const nav_msgs::Odometry::ConstPtr& m) { recording.poses.push_back(*m); });
  auto planes_sub = nh.subscribe<visualization_msgs::MarkerArray>(
      node + "/planes", 1, [&](const visualization_msgs::MarkerArray::ConstPtr& m) {
        recording.plane_markers = m->markers.size();
      });
  auto status_sub = nh.subscribe<std_msgs::String>(
      node + "/status", 1000,
      [&](const std_msgs::String::ConstPtr& m) { recording.status = m->data; });

  // Wait until the node listens on every topic (and our subscriptions are connected).
  const ros::WallTime start = ros::WallTime::now();
  const auto connected = [&] {
    for (const auto& [topic, publisher] : publishers) {
      if (publisher.getNumSubscribers() == 0) return false;
    }
    return odometry_sub.getNumPublishers() > 0;
  };
  while (ros::ok() && !connected() && (ros::WallTime::now() - start).toSec() < timeout) {
    ros::spinOnce();
    ros::WallDuration(0.05).sleep();
  }
  if (!connected()) {
    std::fprintf(stderr, "player: the node did not subscribe within %.0f s\n", timeout);
    return 1;
  }
  PlayFrames(frames, publishers, rate_hz);
  while (ros::ok() && recording.poses.size() < frames.size() &&
         (ros::WallTime::now() - start).toSec() < timeout) {
    ros::spinOnce();
    ros::WallDuration(0.05).sleep();
  }
  if (!WriteKittiPoses(argv[4], recording.poses)) return 1;
  std::printf(
      "player: %zu frames played at %.1f Hz, %zu poses received, %zu plane markers, last "
      "status \"%s\"\n",
      frames.size(), rate_hz, recording.poses.size(), recording.plane_markers,
      recording.status.c_str());
  return recording.poses.size() == frames.size() ? 0 : 1;
}
