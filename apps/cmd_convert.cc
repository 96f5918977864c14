// `planeloc convert kitti-to-bag`: a KITTI-layout stereo folder as a ROS 1 bag that `planeloc run
// --bag` and planeloc_node read (rectified images and camera info; ros/bag_writer.h).
#include <spdlog/spdlog.h>

#include <memory>
#include <string>

#include "command_registry.h"
#include "flags.h"
#include "planeloc/io/kitti_sequence.h"
#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"
#ifdef PLANELOC_HAVE_ROS
#include "planeloc/ros/bag_sequence.h"
#include "planeloc/ros/bag_writer.h"
#endif

namespace planeloc::cli {
namespace {

struct ConvertArgs {
  std::string sequence;
  std::string out;
  std::string cameras = "auto";
  std::string encoding = "mono8";
  std::string left_topic = "/stereo/left/image_rect";
  std::string right_topic = "/stereo/right/image_rect";
  double start_time = 1000.0;
  int frames = 0;
};

int KittiToBag(const ConvertArgs& args) {
  CheckFlag(args.frames >= 0, "--frames", args.frames, "a frame count >= 0 (0 = all frames)",
            "e.g. --frames 20");
  CheckFlag(AtLeast(args.start_time, 1e-9), "--start-time", args.start_time, "seconds > 0",
            "e.g. --start-time 1000");
  CheckFlag(!args.left_topic.empty() && args.left_topic != args.right_topic, "--left-topic",
            args.left_topic, "two different topics for the left and right images",
            "e.g. --left-topic /stereo/left/image_rect --right-topic /stereo/right/image_rect");
  CheckOutputPaths({{"--out", args.out}}, {{"--sequence", args.sequence}});
#ifdef PLANELOC_HAVE_ROS
  const KittiSequence sequence =
      KittiSequence::Open(args.sequence, ParseCameraChoice(args.cameras));
  ros::BagWriteOptions options;
  options.encoding = args.encoding;
  options.left_topic = args.left_topic;
  options.right_topic = args.right_topic;
  options.start_time = args.start_time;
  options.max_frames = args.frames;
  const int frames = ros::WriteStereoBag(sequence, args.out, options);
  spdlog::info("convert: {} stereo frames ({}) -> {}: {} and {}, camera info on {} and {}", frames,
               args.encoding, args.out, args.left_topic, args.right_topic,
               ros::CameraInfoTopicFor(args.left_topic), ros::CameraInfoTopicFor(args.right_topic));
  return 0;
#else
  throw InputError(args.out, 0, "this planeloc was built without ROS 1: cannot write a bag",
                   "install the ROS packages (scripts/setup.sh) and reconfigure (cmake -S . -B "
                   "build)");
#endif
}

const CommandRegistrar kRegistrar("convert", [](CLI::App& app) -> CommandRunner {
  auto args = std::make_shared<ConvertArgs>();
  CLI::App* cmd = app.add_subcommand("convert", "Convert between dataset formats");
  cmd->require_subcommand(1);
  CLI::App* bag = cmd->add_subcommand(
      "kitti-to-bag",
      "A KITTI-layout stereo folder as a ROS 1 bag (rectified images + camera info) for `run "
      "--bag` and planeloc_node (needs a build with ROS)");
  bag->add_option("--sequence", args->sequence, "KITTI odometry sequence or raw drive folder")
      ->required();
  bag->add_option("--out", args->out, "Output bag")->required();
  bag->add_option("--cameras", args->cameras, "auto | grey | color")
      ->check(CLI::IsMember({"auto", "grey", "gray", "color", "colour"}))
      ->capture_default_str();
  bag->add_option("--encoding", args->encoding,
                  "mono8 | rgb8 | bgr8 (sensor_msgs/Image) | png | jpeg (CompressedImage)")
      ->check(CLI::IsMember({"mono8", "rgb8", "bgr8", "png", "jpeg"}))
      ->capture_default_str();
  bag->add_option("--left-topic", args->left_topic, "Left image topic")->capture_default_str();
  bag->add_option("--right-topic", args->right_topic, "Right image topic")->capture_default_str();
  bag->add_option("--start-time", args->start_time,
                  "Header stamp of a frame = this + its sequence time (seconds)")
      ->capture_default_str();
  bag->add_option("--frames", args->frames, "Write only the first N frames (0 = all)");
  return [args] { return KittiToBag(*args); };
});

}  // namespace
}  // namespace planeloc::cli
