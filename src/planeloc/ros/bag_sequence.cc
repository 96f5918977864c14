#include "planeloc/ros/bag_sequence.h"

#include <fmt/format.h>
#include <rosbag/bag.h>
#include <rosbag/exceptions.h>
#include <rosbag/message_instance.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <map>
#include <mutex>
#include <optional>

#include "planeloc/ros/ros_conversions.h"
#include "planeloc/util/error.h"

namespace planeloc::ros {
namespace {

constexpr char kImageType[] = "sensor_msgs/Image";
constexpr char kCompressedType[] = "sensor_msgs/CompressedImage";
constexpr char kInfoType[] = "sensor_msgs/CameraInfo";

// The topics of the bag and their message types.
std::map<std::string, std::string> BagTopics(const rosbag::Bag& bag) {
  rosbag::View view(bag);
  std::map<std::string, std::string> topics;
  for (const rosbag::ConnectionInfo* connection : view.getConnections()) {
    topics[connection->topic] = connection->datatype;
  }
  return topics;
}

std::string TopicList(const std::map<std::string, std::string>& topics) {
  std::string list;
  for (const auto& [topic, type] : topics) {
    list += fmt::format("{}{} ({})", list.empty() ? "" : ", ", topic, type);
  }
  return list.empty() ? "none" : list;
}

// Checks that `topic` is in the bag with one of the types; `what` names its role ("--left-topic").
void CheckTopic(const std::map<std::string, std::string>& topics, const std::string& bag,
                const std::string& topic, const std::string& what,
                const std::vector<std::string>& types) {
  const auto found = topics.find(topic);
  CheckInput(
      found != topics.end(), bag, 0,
      fmt::format("{}: topic {} is not in the bag (topics: {})", what, topic, TopicList(topics)),
      fmt::format("pass {} with one of the bag's {} topics", what, types.front()));
  bool typed = false;
  for (const std::string& type : types) typed |= found->second == type;
  CheckInput(typed, bag, 0,
             fmt::format("{}: topic {} holds {}, expected {}", what, topic, found->second,
                         types.front() + (types.size() > 1 ? " or " + types.back() : "")),
             fmt::format("pass {} with a {} topic", what, types.front()));
}

// The header stamp of an image message, in seconds; raw images must have a supported encoding
// (checked here, before any tracking).
double HeaderStamp(const rosbag::MessageInstance& message, const std::string& bag,
                   const std::string& topic) {
  if (message.getDataType() == kCompressedType) {
    return message.instantiate<sensor_msgs::CompressedImage>()->header.stamp.toSec();
  }
  const auto image = message.instantiate<sensor_msgs::Image>();
  CheckInput(IsSupportedEncoding(image->encoding), topic, 0,
             fmt::format("in {}: image encoding \"{}\" is not supported", bag, image->encoding),
             "record mono8, rgb8 or bgr8 images (or sensor_msgs/CompressedImage)");
  return image->header.stamp.toSec();
}

}  // namespace

void BagOptions::Check() const {
  if (left_topic.empty()) throw OptionsError("BagOptions.left_topic: empty");
  if (right_topic.empty()) throw OptionsError("BagOptions.right_topic: empty");
  if (left_topic == right_topic) throw OptionsError("BagOptions: left_topic == right_topic");
  if (!(pair_tolerance >= 0) || !std::isfinite(pair_tolerance)) {
    throw OptionsError("BagOptions.pair_tolerance: must be finite and >= 0 (seconds)");
  }
}

std::string CameraInfoTopicFor(const std::string& image_topic) {
  const std::size_t slash = image_topic.rfind('/');
  return (slash == std::string::npos ? "" : image_topic.substr(0, slash)) + "/camera_info";
}

struct BagSequence::Impl {
  void ReadCameraInfo();
  void ReadImages();
  void MatchPairs(const std::vector<double>& left, const std::vector<double>& right);
  cv::Mat LoadImage(const rosbag::MessageInstance& message, const std::string& topic) const;

  struct Pair {
    double stamp = 0;
    std::size_t left = 0, right = 0;  // into left_ / right_
  };
  std::filesystem::path path_;
  BagOptions options_;
  rosbag::Bag bag_;
  mutable std::mutex read_mutex_;  // guards reads from bag_ after Open
  std::vector<rosbag::MessageInstance> left_, right_;
  std::vector<Pair> pairs_;
  StereoCamera camera_;
  int unpaired_left_ = 0, unpaired_right_ = 0;
};

BagSequence::BagSequence(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
BagSequence::~BagSequence() = default;
std::string BagSequence::name() const { return impl_->path_.string(); }
std::size_t BagSequence::size() const { return impl_->pairs_.size(); }
const StereoCamera& BagSequence::camera() const { return impl_->camera_; }
double BagSequence::timestamp(std::size_t index) const { return impl_->pairs_.at(index).stamp; }
int BagSequence::unpaired_left() const { return impl_->unpaired_left_; }
int BagSequence::unpaired_right() const { return impl_->unpaired_right_; }
const BagOptions& BagSequence::options() const { return impl_->options_; }

std::unique_ptr<BagSequence> BagSequence::Open(const std::filesystem::path& bag,
                                               const BagOptions& options) {
  options.Check();
  auto sequence = std::make_unique<Impl>();
  sequence->path_ = bag;
  sequence->options_ = options;
  BagOptions& o = sequence->options_;
  if (o.left_info_topic.empty()) o.left_info_topic = CameraInfoTopicFor(o.left_topic);
  if (o.right_info_topic.empty()) o.right_info_topic = CameraInfoTopicFor(o.right_topic);
  CheckInput(std::filesystem::is_regular_file(bag), bag.string(), 0, "the bag file does not exist",
             "check the path given to --bag");
  try {
    sequence->bag_.open(bag.string(), rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw InputError(bag.string(), 0, fmt::format("cannot read the bag: {}", e.what()),
                     "pass a ROS 1 bag (format 2.0, `rosbag info` reads it)");
  }
  const std::map<std::string, std::string> topics = BagTopics(sequence->bag_);
  const std::string name = bag.string();
  CheckTopic(topics, name, o.left_topic, "--left-topic", {kImageType, kCompressedType});
  CheckTopic(topics, name, o.right_topic, "--right-topic", {kImageType, kCompressedType});
  CheckTopic(topics, name, o.left_info_topic, "--camera-info-topics (left)", {kInfoType});
  CheckTopic(topics, name, o.right_info_topic, "--camera-info-topics (right)", {kInfoType});
  sequence->ReadCameraInfo();
  sequence->ReadImages();
  return std::unique_ptr<BagSequence>(new BagSequence(std::move(sequence)));
}

void BagSequence::Impl::ReadCameraInfo() {
  // The first message of each camera-info topic (rectified stereo calibration does not change).
  std::optional<sensor_msgs::CameraInfo> left, right;
  rosbag::View view(bag_,
                    rosbag::TopicQuery({options_.left_info_topic, options_.right_info_topic}));
  for (const rosbag::MessageInstance& message : view) {
    auto& slot = message.getTopic() == options_.left_info_topic ? left : right;
    if (!slot) slot = *message.instantiate<sensor_msgs::CameraInfo>();
    if (left && right) break;
  }
  camera_ = StereoCameraFromInfo(*left, *right, options_.left_info_topic, options_.right_info_topic,
                                 options_.assume_rectified);
  spdlog::info(
      "{}: rectified stereo camera from {} and {}: fx {:.3f}, fy {:.3f}, cx {:.3f}, cy {:.3f}, "
      "baseline {:.5f} m, {}x{}",
      path_.string(), options_.left_info_topic, options_.right_info_topic, camera_.fx, camera_.fy,
      camera_.cx, camera_.cy, camera_.baseline, camera_.width, camera_.height);
}

void BagSequence::Impl::ReadImages() {
  std::vector<double> left_stamps, right_stamps;
  rosbag::View view(bag_, rosbag::TopicQuery({options_.left_topic, options_.right_topic}));
  for (const rosbag::MessageInstance& message : view) {
    const bool is_left = message.getTopic() == options_.left_topic;
    const std::string& topic = is_left ? options_.left_topic : options_.right_topic;
    std::vector<double>& stamps = is_left ? left_stamps : right_stamps;
    const double stamp = HeaderStamp(message, path_.string(), topic);
    if (!stamps.empty() && !(stamp > stamps.back())) {
      throw InputError(topic, 0,
                       fmt::format("in {}: image {} has header stamp {:.9f} s, not after the "
                                   "previous image's {:.9f} s (time goes back or repeats)",
                                   path_.string(), stamps.size(), stamp, stamps.back()),
                       "record the bag in header-stamp order (rosbag record does; or sort it "
                       "with `rosbag filter` / a re-stamping script)");
    }
    stamps.push_back(stamp);
    (is_left ? left_ : right_).push_back(message);
  }
  CheckInput(!left_stamps.empty(), options_.left_topic, 0,
             fmt::format("in {}: the topic has no image", path_.string()),
             "pass --left-topic with the left camera's images");
  CheckInput(!right_stamps.empty(), options_.right_topic, 0,
             fmt::format("in {}: the topic has no image", path_.string()),
             "pass --right-topic with the right camera's images");
  MatchPairs(left_stamps, right_stamps);
  if (unpaired_left_ > 0 || unpaired_right_ > 0) {
    spdlog::warn(
        "{}: {} of {} images on {} and {} of {} on {} have no partner within {:.4f} s; they are "
        "not tracked",
        path_.string(), unpaired_left_, left_stamps.size(), options_.left_topic, unpaired_right_,
        right_stamps.size(), options_.right_topic, options_.pair_tolerance);
  }
  CheckInput(!pairs_.empty(), path_.string(), 0,
             fmt::format("no left image on {} has a right image on {} within {:.4f} s",
                         options_.left_topic, options_.right_topic, options_.pair_tolerance),
             "check the topics, or widen --pair-tolerance");
  spdlog::info("{}: {} stereo frames ({} to {}, pair tolerance {:.4f} s)", path_.string(),
               pairs_.size(), options_.left_topic, options_.right_topic, options_.pair_tolerance);
}

void BagSequence::Impl::MatchPairs(const std::vector<double>& left,
                                   const std::vector<double>& right) {
  // Both lists increase: one merge, each image in at most one pair.
  std::size_t i = 0, j = 0;
  while (i < left.size() && j < right.size()) {
    if (std::abs(left[i] - right[j]) <= options_.pair_tolerance) {
      pairs_.push_back({left[i], i, j});
      ++i;
      ++j;
    } else if (left[i] < right[j]) {
      ++unpaired_left_;
      ++i;
    } else {
      ++unpaired_right_;
      ++j;
    }
  }
  unpaired_left_ += static_cast<int>(left.size() - i);
  unpaired_right_ += static_cast<int>(right.size() - j);
}

cv::Mat BagSequence::Impl::LoadImage(const rosbag::MessageInstance& message,
                                     const std::string& topic) const {
  // rosbag::Bag reads every message through one file handle and shared chunk buffers, so reads
  // take turns; the decoding, which is most of the time, runs outside the lock.
  sensor_msgs::CompressedImageConstPtr compressed;
  sensor_msgs::ImageConstPtr raw;
  {
    const std::lock_guard<std::mutex> lock(read_mutex_);
    if (message.getDataType() == kCompressedType) {
      compressed = message.instantiate<sensor_msgs::CompressedImage>();
    } else {
      raw = message.instantiate<sensor_msgs::Image>();
    }
  }
  cv::Mat image = compressed ? GreyImage(*compressed, topic) : GreyImage(*raw, topic);
  CheckInput(image.cols == camera_.width && image.rows == camera_.height, topic, 0,
             fmt::format("in {}: the image is {}x{}, the camera info says {}x{}", path_.string(),
                         image.cols, image.rows, camera_.width, camera_.height),
             "record the rectified images with their own camera info");
  return image;
}

StereoPair BagSequence::LoadStereoPair(std::size_t index) const {
  const Impl::Pair& pair = impl_->pairs_.at(index);
  return {impl_->LoadImage(impl_->left_[pair.left], impl_->options_.left_topic),
          impl_->LoadImage(impl_->right_[pair.right], impl_->options_.right_topic)};
}

}  // namespace planeloc::ros
