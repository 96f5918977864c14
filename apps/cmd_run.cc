// `planeloc run`: stereo visual odometry over a KITTI or ASL/EuRoC sequence or a rosbag (see
// docs/tracking.md).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "command_registry.h"
#include "flags.h"
#include "planeloc/io/asl_sequence.h"
#include "planeloc/pipeline/run_sequence.h"
#include "planeloc/util/allocator.h"
#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"
#ifdef PLANELOC_HAVE_ROS
#include "planeloc/ros/bag_sequence.h"
#endif
#ifdef PLANELOC_HAVE_LIVE_VIEW
#include <csignal>
#include <fstream>
#include <thread>

#include "planeloc/io/trajectory.h"
#include "planeloc/view/live_view.h"
#endif

namespace planeloc::cli {
namespace {

struct RunArgs {
  std::string sequence;
  std::string bag;
  std::string left_topic;
  std::string right_topic;
  std::vector<std::string> camera_info_topics;  // left, right
  double pair_tolerance = 0.005;
  bool assume_rectified = false;
  std::string init_pose_from;
  std::string init_pose;
  bool no_planes = false;
  bool realtime = false;
  std::string planes;
  std::string map_cloud;
  std::string prior;  // planes | depth | hybrid; "" = by the maps given
  std::string init_sigma;
  std::string out;
  std::string format = "kitti";
  std::string stats;
  std::string config;
  bool calib_from_settings = false;
  bool deterministic = false;
  int threads = 0;
  std::string cameras = "auto";
  int frames = 0;
  std::string report_dir;
  std::string map_update;
  std::string out_final;
  bool view = false;         // --view given (with or without an address)
  std::string view_address;  // "", "PORT", "HOST" or "HOST:PORT"
  bool view_wait = false;
  std::string gt;
};

// --report-dir: created when missing (its parent must exist, as for any output folder).
void PrepareReportDir(const std::string& dir) {
  std::error_code error;
  if (std::filesystem::is_directory(dir, error)) return;
  CheckOutputPaths({{"--report-dir", dir}});
  std::filesystem::create_directory(dir, error);
  CheckInput(!error, dir, 0,
             fmt::format("--report-dir: cannot create the folder: {}", error.message()),
             "pass a folder in a writable place");
}

// The frames of --bag (rosbag input, built with ROS 1: cmake/PlanelocRos.cmake).
std::shared_ptr<const StereoSource> OpenBag(const RunArgs& args) {
#ifdef PLANELOC_HAVE_ROS
  CheckInput(!args.left_topic.empty() && !args.right_topic.empty(), args.bag, 0,
             "--bag needs the image topics",
             "pass --left-topic and --right-topic (`rosbag info` lists the bag's topics)");
  CheckFlag(AtLeast(args.pair_tolerance, 0.0), "--pair-tolerance", args.pair_tolerance,
            "seconds >= 0", "e.g. --pair-tolerance 0.005");
  ros::BagOptions options;
  options.left_topic = args.left_topic;
  options.right_topic = args.right_topic;
  if (!args.camera_info_topics.empty()) {
    options.left_info_topic = args.camera_info_topics.at(0);
    options.right_info_topic = args.camera_info_topics.at(1);
  }
  options.pair_tolerance = args.pair_tolerance;
  options.assume_rectified = args.assume_rectified;
  return ros::BagSequence::Open(args.bag, options);
#else
  throw InputError(args.bag, 0, "this planeloc was built without ROS 1: no rosbag input",
                   "install the ROS packages (scripts/setup.sh) and reconfigure (cmake -S . -B "
                   "build), or convert the bag to a KITTI-layout folder");
#endif
}

#ifdef PLANELOC_HAVE_LIVE_VIEW
volatile std::sig_atomic_t interrupted = 0;

// --view's "HOST:PORT", "PORT", "HOST" or "" (loopback, a free port).
view::LiveViewOptions ParseViewAddress(const std::string& address) {
  view::LiveViewOptions options;
  if (address.empty()) return options;
  const std::size_t colon = address.rfind(':');
  std::string host = colon == std::string::npos ? address : address.substr(0, colon);
  std::string port = colon == std::string::npos ? "" : address.substr(colon + 1);
  if (colon == std::string::npos && !address.empty() &&
      address.find_first_not_of("0123456789") == std::string::npos) {
    host.clear();
    port = address;
  }
  if (!host.empty()) options.host = host;
  if (!port.empty()) {
    CheckFlag(port.size() <= 5 && port.find_first_not_of("0123456789") == std::string::npos &&
                  std::stoi(port) >= 1 && std::stoi(port) <= 65535,
              "--view", address, "[HOST:]PORT with a port from 1 to 65535, or a HOST alone",
              "e.g. --view 127.0.0.1:8080, or --view alone for loopback and a free port");
    options.port = std::stoi(port);
  }
  return options;
}

// --gt for the view: one pose per frame, KITTI (12 numbers a line) or TUM (8), by the first line.
std::vector<Eigen::Vector3d> ReadViewGt(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  const TrajectoryFormat format =
      ParseNumberList(line).size() == 8 ? TrajectoryFormat::kTum : TrajectoryFormat::kKitti;
  const Trajectory gt = ReadTrajectory(path, format);
  std::vector<Eigen::Vector3d> positions;
  for (const Rigid3d& pose : gt.world_from_cam) positions.push_back(pose.translation);
  return positions;
}

std::shared_ptr<view::LiveView> StartLiveView(const RunArgs& args) {
  view::LiveViewOptions options = ParseViewAddress(args.view_address);
  if (const char* three = std::getenv("PLANELOC_THREE_JS_DIR")) options.three_js_dir = three;
  if (!args.gt.empty()) options.gt_positions = ReadViewGt(args.gt);
  options.title = "planeloc live \u00b7 " + (args.bag.empty() ? args.sequence : args.bag);
  std::shared_ptr<view::LiveView> live = view::LiveView::Start(options);
  spdlog::info("live view: {} (loopback only unless --view names another address)", live->url());
  return live;
}

// --view-wait: the page stays until Ctrl-C (or SIGTERM).
void ServeUntilInterrupted(const view::LiveView& live) {
  spdlog::info("live view: the run has finished; still serving {} until Ctrl-C", live.url());
  std::signal(SIGINT, [](int) { interrupted = 1; });
  std::signal(SIGTERM, [](int) { interrupted = 1; });
  while (!interrupted) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  spdlog::info("live view: stopped");
}
#endif

// --prior, or the mode the maps given imply: planes with --planes, depth with --map-cloud alone,
// hybrid with both.
std::string PriorMode(const RunArgs& args) {
  if (!args.prior.empty()) return args.prior;
  if (!args.map_cloud.empty()) return args.planes.empty() ? "depth" : "hybrid";
  return args.planes.empty() ? "" : "planes";
}

// The flags' values and combinations, and the outputs' folders, before any work.
void CheckRunArgs(const RunArgs& args) {
  CheckInput(args.sequence.empty() != args.bag.empty(), "", 0,
             args.bag.empty() ? "no input given" : "--sequence and --bag given together",
             "pass either --sequence (a KITTI-layout folder) or --bag (a ROS 1 bag)");
  if (args.prior.empty() && args.planes.empty() && args.map_cloud.empty() && !args.no_planes) {
    throw InputError("", 0, "no prior map given",
                     "pass --planes planes.json (from `planeloc map planes`), --map-cloud map.pcd "
                     "(the depth prior) or --no-planes (visual odometry only)");
  }
  const std::string prior = PriorMode(args);
  if (prior == "hybrid") {
    CheckInput(!args.planes.empty() && !args.map_cloud.empty(), "", 0,
               "--prior hybrid needs both the plane map and the LiDAR map cloud",
               "add --planes planes.json and --map-cloud map.pcd (from `planeloc map planes` and "
               "`planeloc map build`)");
    CheckInput(!args.no_planes, "", 0, "--no-planes and --prior hybrid given together",
               "drop --no-planes, or drop --prior hybrid for visual odometry");
  }
  if (prior == "depth") {
    CheckInput(!args.map_cloud.empty(), "", 0, "--prior depth needs the LiDAR map cloud",
               "add --map-cloud map.pcd (from `planeloc map build`)");
    CheckInput(args.planes.empty(), args.planes, 0,
               "--prior depth uses the map cloud alone; the plane map would be ignored",
               "drop --planes, or use --prior planes");
    CheckInput(!args.no_planes, "", 0, "--no-planes and --map-cloud given together",
               "drop --no-planes to use the depth prior, or --map-cloud for visual odometry");
  }
  if (prior == "planes") {
    CheckInput(!args.planes.empty(), "", 0, "--prior planes needs a plane map",
               "add --planes planes.json (from `planeloc map planes`), or use --prior depth");
    CheckInput(args.map_cloud.empty(), args.map_cloud, 0,
               "--prior planes uses the plane map alone; the map cloud would be ignored",
               "drop --map-cloud, or use --prior depth without --planes");
  }
  CheckFlag(args.threads >= 0 && args.threads <= 1024, "--threads", args.threads,
            "a thread count from 0 to 1024 (0 = the settings' default of 2)", "e.g. --threads 2");
  CheckFlag(args.frames >= 0, "--frames", args.frames, "a frame count >= 0 (0 = all frames)",
            "e.g. --frames 100");
  // Before any work: a missing output folder or two outputs on one file fail now, not after the
  // run (the settings echo is written first and used to take the blame).
  if (!args.map_update.empty() && args.planes.empty()) {
    throw InputError(args.map_update, "--map-update reports on the planes of a plane map",
                     "add --planes planes.json (or drop --map-update)");
  }
  if (!args.view && (args.view_wait || !args.gt.empty())) {
    throw InputError("", 0, args.view_wait ? "--view-wait needs --view" : "--gt needs --view",
                     "add --view (the live view in the browser), or drop the flag");
  }
#ifndef PLANELOC_HAVE_LIVE_VIEW
  if (args.view) {
    throw InputError("", 0, "this planeloc was built without the live view (cpp-httplib)",
                     "install libcpp-httplib-dev (./scripts/setup.sh) and reconfigure (cmake -S "
                     ". -B build)");
  }
#endif
  CheckOutputPaths({{"--out", args.out},
                    {"--stats", args.stats},
                    {"--map-update", args.map_update},
                    {"--out-final", args.out_final},
                    {"the settings echo (--out + .config.yaml)", args.out + ".config.yaml"}},
                   {{"--init-pose-from", args.init_pose_from},
                    {"--planes", args.planes},
                    {"--map-cloud", args.map_cloud},
                    {"--config", args.config},
                    {"--bag", args.bag},
                    {"--gt", args.gt}});
}

// Opens --bag: call after the checks of CheckRunArgs.
RunOptions MakeRunOptions(const RunArgs& args) {
  RunOptions options;
  options.sequence = args.sequence;
  if (!args.bag.empty()) options.source = OpenBag(args);
  options.cameras = ParseCameraChoice(args.cameras);
  if (!args.init_pose_from.empty() &&
      std::filesystem::path(args.init_pose_from).extension() == ".csv") {
    // An ASL/EuRoC ground truth: the body's pose at frame 0's time, through the rig's T_BS.
    CheckInput(args.bag.empty() && AslSequence::IsAslFolder(args.sequence), args.init_pose_from, 0,
               "a EuRoC ground-truth csv gives the body's pose: it needs the ASL sequence's "
               "T_BS (--sequence MAV0)",
               "pass --sequence the mav0 folder this ground truth belongs to, or a KITTI/TUM "
               "pose file");
    auto asl = std::make_shared<AslSequence>(AslSequence::Open(args.sequence));
    options.world_from_cam_initial = asl->CameraPoseFromGroundTruth(args.init_pose_from, 0);
    options.source = std::move(asl);
  } else if (!args.init_pose_from.empty()) {
    options.world_from_cam_initial = ReadFirstPose(args.init_pose_from);
  } else if (!args.init_pose.empty()) {
    options.world_from_cam_initial = ParsePose12(args.init_pose);
  }
  options.trajectory_path = args.out;
  options.format = ParseTrajectoryFormat(args.format);
  if (!args.stats.empty()) {
    options.stats_path = args.stats;
    options.summary_path = args.stats + ".summary.json";
  } else if (!args.report_dir.empty()) {
    options.stats_path = std::filesystem::path(args.report_dir) / "stats.jsonl";
    options.summary_path = std::filesystem::path(args.report_dir) / "summary.json";
  }
  if (!args.report_dir.empty()) options.report_dir = args.report_dir;
  if (!args.config.empty()) options.settings_path = args.config;
  options.calibration_from_settings = args.calib_from_settings;
  if (!args.planes.empty()) options.planes_path = args.planes;
  if (!args.map_update.empty()) options.map_update_path = args.map_update;
  if (!args.out_final.empty()) options.final_trajectory_path = args.out_final;
  if (!args.map_cloud.empty()) options.map_cloud_path = args.map_cloud;
  if (!args.init_sigma.empty() && args.no_planes) {
    spdlog::warn(
        "--init-sigma is used only with --planes: visual odometry runs in the frame of "
        "the initial pose");
  }
  if (!args.init_sigma.empty() && options.map_cloud_path && !options.planes_path) {
    spdlog::warn(
        "--init-sigma is used only with --planes (the map lock): the depth prior starts from the "
        "initial pose as given and refines it frame by frame (docs/depth-prior.md)");
  }
  if (options.planes_path) {
    // A GNSS-like start by default: the run finds its pose in the plane map.
    options.start_prior = ParseInitSigma(args.init_sigma.empty() ? "2 0.5 5" : args.init_sigma);
  }
  options.deterministic = args.deterministic;
  options.threads = args.threads;
  options.max_frames = args.frames;
  options.realtime = args.realtime;
  return options;
}

void LogRunSummary(const RunSummary& summary) {
  spdlog::info(
      "{} frames in {:.1f} s ({:.1f} fps): {} tracked, {} lost, {} skipped, {} keyframes, "
      "{:.0f} tracked points per frame, median BA reprojection error {:.3f} px",
      summary.frames, summary.seconds, summary.frames / std::max(summary.seconds, 1e-9),
      summary.tracked, summary.lost, summary.skipped, summary.keyframes,
      summary.mean_tracked_points, summary.median_ba_reprojection_px);
  if (summary.latency_p50_ms) {
    spdlog::info(
        "real-time replay: latency from a frame's arrival to its pose p50 {:.1f} ms, "
        "p99 {:.1f} ms, max {:.1f} ms",
        *summary.latency_p50_ms, *summary.latency_p99_ms, *summary.latency_max_ms);
  }
  spdlog::info(
      "local BA of the {} keyframes: {} applied, {} superseded (worker busy), {} discarded (map "
      "moved), {} unusable, {} empty; {} keyframes and {} points of late results left as they "
      "were (moved since the snapshot)",
      summary.ba.keyframes, summary.ba.applied, summary.ba.superseded, summary.ba.discarded,
      summary.ba.unusable, summary.ba.empty, summary.ba.stale_keyframes, summary.ba.stale_points);
}

void LogPlaneMapSummary(const RunSummary& summary, const RunOptions& options,
                        const std::string& planes_path) {
  spdlog::info(
      "plane map: {} planes, {:.0f} point-to-plane residuals per local BA on average, {} "
      "planes disabled (biased), {} map moves by the planes' consensus on the trajectory's "
      "offset",
      summary.planes, summary.mean_ba_plane_residuals, summary.planes_disabled,
      summary.consensus_corrections);
  if (summary.crease_keyframes > 0) {
    spdlog::info(
        "crease check (LSD): {} keyframes, {:.1f} visible / {:.1f} confirmed creases per "
        "keyframe, median edge distance {}",
        summary.crease_keyframes, summary.mean_visible_creases, summary.mean_confirmed_creases,
        summary.median_edge_px ? fmt::format("{:.2f} px", *summary.median_edge_px) : "-");
  }
  if (options.start_prior.Exact()) {
    spdlog::info("map lock: exact start (--init-sigma \"0 0 0\"), plane constraints from frame 0");
  }
  for (const LockEvent& event : summary.lock_events) {
    const Eigen::Vector3d t = event.map_from_world.translation;
    spdlog::info(
        "map lock: {} at frame {} (keyframes from {}): correction {:.3f} m [{:.3f} {:.3f} "
        "{:.3f}], {:.3f} deg",
        event.recorrection ? "re-registered" : MapLockName(event.lock), event.frame,
        event.first_keyframe_id, t.norm(), t.x(), t.y(), t.z(),
        RotationAngle(event.map_from_world.rotation, Eigen::Quaterniond::Identity()) * 180.0 /
            std::numbers::pi);
  }
  if (!options.start_prior.Exact()) {
    std::string reasons;
    for (const auto& [reason, count] : summary.lock_refusals) {
      reasons += fmt::format("{}{} ({}x)", reasons.empty() ? "" : "; ", reason, count);
    }
    if (summary.lock_attempts > 0) {
      spdlog::info("map lock: {} registration attempts before the lock{}{}", summary.lock_attempts,
                   reasons.empty() ? "" : "; not applied: ", reasons);
    }
    if (summary.final_map_lock == "searching") {
      spdlog::warn(
          "{}: the run never registered itself to the plane map (map lock: searching); the "
          "trajectory is visual odometry in the frame of the initial pose. The planes in view "
          "may not constrain the pose (only the road, or planes far away), or the initial pose "
          "is farther off than --init-sigma says.",
          planes_path);
    } else {
      spdlog::info("map lock at the end: {}", summary.final_map_lock);
    }
  }
  if (summary.planes > 0 && summary.keyframes > 1 && summary.mean_ba_plane_residuals < 1.0 &&
      summary.final_map_lock != "searching") {
    spdlog::warn(
        "{}: almost no map point lay on a plane of the map; is the plane map in the frame of "
        "the initial pose? (give --init-pose-from the poses the map was built with)",
        planes_path);
  }
}

int Run(const RunArgs& args) {
  CheckRunArgs(args);
  if (!args.report_dir.empty()) PrepareReportDir(args.report_dir);
  KeepFreedMemoryForReuse();
  RunOptions options = MakeRunOptions(args);
#ifdef PLANELOC_HAVE_LIVE_VIEW
  // Before the run: a taken port fails now (exit 2), not after the work.
  std::shared_ptr<view::LiveView> live;
  if (args.view) {
    live = StartLiveView(args);
    options.observer = live;
  }
#endif
  const RunSummary summary = RunSequence(options);
  LogRunSummary(summary);
  if (options.planes_path) LogPlaneMapSummary(summary, options, args.planes);
  if (options.map_cloud_path) {
    spdlog::info(
        "depth prior: {} of {} frames refined against the map cloud ({} points), {:.0f} map "
        "points per refined frame, {} refinements refused (beyond DepthPrior.maxCorrection)",
        summary.depth_frames, summary.frames, summary.map_cloud_points, summary.mean_depth_points,
        summary.depth_refused);
  }
  spdlog::info("trajectory: {}", args.out);
  const std::string input = args.bag.empty() ? args.sequence : args.bag;
  // A few skipped frames are bridged by the motion model; a trajectory mostly extrapolated is not
  // a result (e.g. a right camera that went black after frame 0).
  CheckInput(2 * summary.skipped <= summary.frames, input, 0,
             fmt::format("{} of {} frames were skipped (images missing, corrupt, blank or of "
                         "another size; the warnings above name them): the trajectory in {} is "
                         "mostly extrapolated",
                         summary.skipped, summary.frames, args.out),
             "repair or re-extract the images named above, or track a stretch without them "
             "(--frames)");
#ifdef PLANELOC_HAVE_LIVE_VIEW
  if (live && args.view_wait) ServeUntilInterrupted(*live);
  if (live) live->Stop();
#endif
  return 0;
}

const CommandRegistrar kRegistrar("run", [](CLI::App& app) -> CommandRunner {
  auto args = std::make_shared<RunArgs>();
  CLI::App* cmd = app.add_subcommand(
      "run", "Track a stereo sequence (visual odometry, or localization in a plane map)");
  cmd->add_option("--sequence", args->sequence,
                  "KITTI odometry sequence folder, raw drive folder, or ASL/EuRoC folder (mav0 "
                  "or the folder holding it; raw pairs rectified on load) (or --bag)");
  cmd->add_option("--bag", args->bag,
                  "ROS 1 bag of rectified stereo images (sensor_msgs/Image mono8/rgb8/bgr8 or "
                  "CompressedImage) and their camera info (needs a build with ROS)");
  cmd->add_option("--left-topic", args->left_topic, "--bag: the left camera's image topic");
  cmd->add_option("--right-topic", args->right_topic, "--bag: the right camera's image topic");
  cmd->add_option("--camera-info-topics", args->camera_info_topics,
                  "--bag: LEFT RIGHT sensor_msgs/CameraInfo topics (default: each image topic's "
                  "namespace + /camera_info)")
      ->expected(2);
  cmd->add_option("--pair-tolerance", args->pair_tolerance,
                  "--bag: seconds between a left and a right header stamp of one stereo frame; "
                  "images without a partner are counted and skipped")
      ->capture_default_str();
  cmd->add_flag("--assume-rectified", args->assume_rectified,
                "--bag: the image topics are rectified although the camera info has the raw "
                "camera's distortion D and rectification R (image_rect with the raw camera_info)");
  auto* from = cmd->add_option("--init-pose-from", args->init_pose_from,
                               "KITTI/TUM pose file whose first pose is frame 0's world_from_cam, "
                               "or, with an ASL --sequence, its ground-truth csv (the body pose "
                               "at frame 0's time through cam0's T_BS)");
  auto* pose = cmd->add_option("--init-pose", args->init_pose,
                               "\"12 numbers\": frame 0's world_from_cam, row-major 3x4");
  from->excludes(pose);
  auto* no_planes = cmd->add_flag("--no-planes", args->no_planes, "Visual odometry only");
  auto* planes = cmd->add_option(
      "--planes", args->planes,
      "Plane map (planes.json of `planeloc map planes`, in the frame of the initial pose)");
  no_planes->excludes(planes);
  cmd->add_option("--map-cloud", args->map_cloud,
                  "LiDAR map cloud (.pcd/.ply/.xyz, e.g. from `planeloc map build`, in the frame "
                  "of the initial pose): each frame's pose is refined by the depth-to-map "
                  "residual of dense stereo against the map (--prior depth; docs/depth-prior.md)");
  cmd->add_option("--prior", args->prior,
                  "planes | depth | hybrid: which prior map constrains the pose. Default: planes "
                  "with --planes alone, depth with --map-cloud alone, hybrid with both "
                  "(docs/depth-prior.md)")
      ->check(CLI::IsMember({"planes", "depth", "hybrid"}));
  cmd->add_option("--init-sigma", args->init_sigma,
                  "\"S_XY S_Z S_YAW_DEG\": how well the initial pose is known in the plane map "
                  "(metres horizontal, metres vertical, degrees of heading; roll and pitch come "
                  "from the road). With --planes the default is \"2 0.5 5\" (GNSS-like): the run "
                  "registers its stereo structure to the plane map and moves into the map frame "
                  "when it locks. \"0 0 0\": the initial pose is exact (no registration). The "
                  "registration searches at most S_XY <= 10 m, S_Z <= 2 m, S_YAW_DEG <= 15 deg; "
                  "wider values are refused (exit 2)");
  cmd->add_option("--out", args->out, "Output trajectory (one pose per frame)")->required();
  cmd->add_option("--out-final", args->out_final,
                  "Also write, at the end, the trajectory in the map frame as the run knows it "
                  "then: the frames tracked before the map lock (in the frame of the start "
                  "prior) re-expressed by the lock's correction. --out keeps each frame as it was "
                  "tracked (docs/map-registration.md)");
  cmd->add_option("--format", args->format, "kitti | tum")
      ->check(CLI::IsMember({"kitti", "tum"}))
      ->capture_default_str();
  cmd->add_option("--stats", args->stats,
                  "Per-frame statistics, JSON lines (and the end-of-run summary in "
                  "<stats>.summary.json)");
  cmd->add_option(
      "--config", args->config,
      "Settings file: ORB-SLAM2 or ORB-SLAM3 stereo settings YAML and/or planeloc keys");
  cmd->add_flag("--calib-from-settings", args->calib_from_settings,
                "Use the --config file's intrinsics and baseline instead of the sequence's "
                "calibration");
  cmd->add_flag("--deterministic", args->deterministic, "Local BA in line: bit-identical runs");
  cmd->add_flag("--realtime", args->realtime,
                "Replay at the camera's rate (times.txt): each frame is read only when it would "
                "arrive from a live camera, none is dropped, and the latency from its arrival to "
                "its pose is logged (p50 / p99 / max) and written to --stats (latency_ms)");
  cmd->add_option("--threads", args->threads, "Threads (0 = settings' default of 2)");
  cmd->add_option("--cameras", args->cameras, "auto | grey | color")
      ->check(CLI::IsMember({"auto", "grey", "gray", "color", "colour"}))
      ->capture_default_str();
  cmd->add_option("--frames", args->frames, "Track only the first N frames (0 = all)");
  cmd->add_option("--report-dir", args->report_dir,
                  "Also write the folder `planeloc report` reads: trajectory, stats, settings, "
                  "plane map and a few keyframe overlay images (created if missing)");
  cmd->add_option("--map-update", args->map_update,
                  "With --planes: write what the run learned about each plane (unseen, "
                  "confirmed, corrected with offset and normal and their sigma, contradicted; the "
                  "frames it was seen in) as JSON for `planeloc map update` (docs/map-update.md)");
  auto* view = cmd->add_option(
      "--view", args->view_address,
      "Watch the run live in a browser: serves one page on [HOST:]PORT (default 127.0.0.1 and a "
      "free port; the address is logged) with the plane map, the trajectory so far, the current "
      "image with its features and the projected planes, the lock state, fps and stage times "
      "(docs/live-view.md). A given port that is taken is exit 2");
  view->expected(0, 1);
  cmd->add_flag("--view-wait", args->view_wait,
                "With --view: keep serving the page after the run until Ctrl-C");
  cmd->add_option("--gt", args->gt,
                  "With --view: ground-truth poses (KITTI or TUM, one per frame): the live "
                  "trajectory is coloured by its position error");
  return [args, view] {
    args->view = view->count() > 0;
    return Run(*args);
  };
});

}  // namespace
}  // namespace planeloc::cli
