#include "planeloc/pipeline/run_sequence.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <tbb/global_control.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <numbers>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <thread>

#include "planeloc/io/asl_sequence.h"
#include "planeloc/io/initial_pose.h"
#include "planeloc/io/map_updates.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/io/point_cloud.h"
#include "planeloc/pipeline/final_trajectory.h"
#include "planeloc/pipeline/keyframe_overlay.h"
#include "planeloc/pipeline/run_checks.h"
#include "planeloc/util/error.h"
#include "planeloc/util/progress.h"
#include "planeloc/util/safe_file.h"

namespace planeloc {
namespace {

std::string ReadWhole(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  CheckInput(static_cast<bool>(in), path.string(), 0, "cannot read the file back for the report",
             "check that the file was written and is readable");
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Copies `from` into the report folder unless it was written there already.
void CopyInto(const std::filesystem::path& from, const std::filesystem::path& to) {
  std::error_code error;
  if (std::filesystem::equivalent(from, to, error)) return;
  WriteFileWhole(to, ReadWhole(from));
}

// Up to `count` keyframes spread over the run. Preferably where the pose is in the plane map's
// frame (after the map lock, or every keyframe without a registration); a run that never locked
// shows its keyframes in the frame of the initial pose (the overlay then shows how far off it is).
std::vector<int> OverlayFrames(const std::vector<FrameStats>& stats, int count) {
  // 0: in the map frame (locked, or no registration), 1: partly, 2: not yet.
  const auto rank = [](const std::string& lock) {
    return lock.empty() || lock == "locked" ? 0 : lock == "partial" ? 1 : 2;
  };
  std::vector<int> frames;
  for (int accepted = 0; accepted <= 2 && frames.empty() && count > 0; ++accepted) {
    std::vector<int> candidates;
    for (const FrameStats& s : stats) {
      if (s.keyframe && !s.skipped && rank(s.map_lock) <= accepted) candidates.push_back(s.frame);
    }
    const int n = std::min<int>(count, candidates.size());
    for (int k = 0; k < n; ++k) {
      const int index = static_cast<int>((k + 0.5) * candidates.size() / n);
      frames.push_back(candidates[std::min<std::size_t>(index, candidates.size() - 1)]);
    }
  }
  return frames;
}

struct EffectiveSettings {
  TrackerOptions options;
  StereoCamera camera;
  bool calibration_from_settings = false;
  std::shared_ptr<const StereoRectifier> rectifier;  // raw images: rectified on load
};

// Reads the settings file before anything slow, so that a bad file fails first.
std::optional<SettingsFile> ReadSettings(const RunOptions& run) {
  CheckInput(run.settings_path || !run.calibration_from_settings, "", 0,
             "--calib-from-settings needs a settings file",
             "pass --config settings.yaml with the camera keys, or drop --calib-from-settings");
  if (!run.settings_path) return std::nullopt;
  return LoadTrackerSettings(*run.settings_path, TrackerOptions{});
}

EffectiveSettings Effective(const RunOptions& run, std::optional<SettingsFile> file,
                            const StereoCamera& sequence_camera) {
  EffectiveSettings effective;
  effective.camera = sequence_camera;
  if (file) {
    const std::string path = run.settings_path->string();
    effective.calibration_from_settings =
        run.calibration_from_settings || file->calibration_from_settings;
    effective.camera = ChooseCamera(sequence_camera, file->camera,
                                    effective.calibration_from_settings, path, &file->warnings);
    if (file->camera && file->camera->rectifier) {
      effective.rectifier = file->camera->rectifier;
      effective.calibration_from_settings = true;
      spdlog::info(
          "{}: raw stereo images, rectified on load (fx {:.3f}, cx {:.3f}, cy {:.3f}, baseline "
          "{:.5f} m); the sequence's calibration is not used",
          path, effective.camera.fx, effective.camera.cx, effective.camera.cy,
          effective.camera.baseline);
    }
    for (const auto& warning : file->warnings) spdlog::warn("{}: {}", path, warning);
    if (!file->ignored.empty()) {
      std::string keys;
      for (const auto& key : file->ignored) keys.append(keys.empty() ? "" : ", ").append(key);
      spdlog::info("{}: not used by planeloc (ignored): {}", path, keys);
    }
    effective.options = file->options;
  }
  TrackerOptions& options = effective.options;
  if (run.deterministic) options.deterministic = true;
  // Frames from a live camera never wait for the local BA (LocalBA.maxLagFrames bounds how far
  // the BA may fall behind frames that come as fast as they decode; at the camera's rate it keeps
  // up by itself: docs/bench-tracking.md, "Real-time replay").
  if (run.realtime) options.ba_max_lag_frames = 0;
  if (run.threads > 0) options.num_threads = run.threads;
  if (run.map_update_path) options.record_plane_evidence = true;
  options.Check();
  return effective;
}

void WriteReportFolder(const RunOptions& run, const RunSummary& summary,
                       const StereoSource& sequence, const EffectiveSettings& effective,
                       const PlaneMap* plane_map) {
  namespace fs = std::filesystem;
  const fs::path& dir = *run.report_dir;
  nlohmann::json meta = {{"mode", plane_map ? "planes" : "vo"},
                         {"sequence", run.source ? sequence.name() : run.sequence.string()},
                         {"format", run.format == TrajectoryFormat::kKitti ? "kitti" : "tum"},
                         {"frames", summary.frames}};
  WriteFileWhole(dir / "run.json", meta.dump(2) + '\n');
  CopyInto(run.trajectory_path, dir / "trajectory.txt");
  if (run.stats_path) CopyInto(*run.stats_path, dir / "stats.jsonl");
  if (run.summary_path) CopyInto(*run.summary_path, dir / "summary.json");
  const fs::path settings = run.trajectory_path.string() + ".config.yaml";
  if (run.write_effective_settings) CopyInto(settings, dir / "settings.yaml");
  if (run.planes_path) CopyInto(*run.planes_path, dir / "planes.json");
  if (run.map_update_path) CopyInto(*run.map_update_path, dir / "map_update.json");

  const std::vector<int> frames = OverlayFrames(summary.stats, run.report_keyframe_images);
  if (frames.empty()) return;
  std::error_code error;
  fs::create_directories(dir / "keyframes", error);
  CheckInput(!error, (dir / "keyframes").string(), 0,
             fmt::format("cannot create the folder: {}", error.message()),
             "check that --report-dir is writable");
  for (const int frame : frames) {
    if (frame < 0 || static_cast<std::size_t>(frame) >= summary.world_from_cam.size()) continue;
    StereoPair pair;
    try {
      pair = sequence.LoadStereoPair(frame);
      if (effective.rectifier) pair = effective.rectifier->Rectify(pair);
    } catch (const InputError& e) {
      spdlog::warn("report: no overlay of keyframe {}: {}", frame, e.what());
      continue;
    }
    KeyframeOverlayCounts counts;
    const cv::Mat overlay =
        DrawKeyframeOverlay(pair.left, pair.right, summary.camera, summary.world_from_cam[frame],
                            plane_map, summary.options, &counts);
    // JPEG: a third of the PNG's size for a photo, and the report inlines every image.
    std::vector<uchar> jpeg;
    cv::imencode(".jpg", overlay, jpeg, {cv::IMWRITE_JPEG_QUALITY, 88});
    // The map lock in the name: the report's caption says where the pose stood.
    const std::string& lock = summary.stats[frame].map_lock;
    const std::string name =
        fmt::format("keyframe_{:06d}{}.jpg", frame, lock.empty() ? "" : "_map_lock_" + lock);
    WriteFileWhole(dir / "keyframes" / name,
                   std::string_view(reinterpret_cast<const char*>(jpeg.data()), jpeg.size()));
  }
}

}  // namespace

StartPrior ParseInitSigma(const std::string& text) {
  const std::vector<double> v = ParseNumberList(text);
  StartPrior prior;
  const bool valid = v.size() == 3 && std::all_of(v.begin(), v.end(), [](double x) {
                       return std::isfinite(x) && x >= 0.0;
                     });
  CheckInput(valid, "--init-sigma", 0,
             "expected three finite numbers >= 0 \"S_XY S_Z S_YAW_DEG\" (metres horizontal, "
             "metres vertical, degrees of heading), got \"" +
                 text + "\"",
             "pass e.g. --init-sigma \"2 0.5 5\" (a GNSS-like start) or \"0 0 0\" (exact start)");
  const bool searchable = v[0] <= StartPrior::kMaxSigmaHorizontal &&
                          v[1] <= StartPrior::kMaxSigmaVertical &&
                          v[2] <= StartPrior::kMaxSigmaYawDeg;
  CheckInput(searchable, "--init-sigma", 0,
             fmt::format("\"{}\" is beyond what the map registration can search: S_XY <= {} m, "
                         "S_Z <= {} m, S_YAW_DEG <= {} deg",
                         text, StartPrior::kMaxSigmaHorizontal, StartPrior::kMaxSigmaVertical,
                         StartPrior::kMaxSigmaYawDeg),
             "give the start within those bounds (e.g. from GNSS), or \"0 0 0\" for an exact "
             "start");
  prior.sigma_horizontal = v[0];
  prior.sigma_vertical = v[1];
  prior.sigma_yaw_deg = v[2];
  return prior;
}

namespace {

// Nearest-rank percentile (p in (0, 1]) of a non-empty sorted vector.
double Percentile(const std::vector<double>& sorted, double p) {
  const auto rank = static_cast<std::size_t>(std::ceil(p * static_cast<double>(sorted.size())));
  return sorted[std::clamp<std::size_t>(rank, 1, sorted.size()) - 1];
}

// The end-of-run counts and medians of the frames' stats.
void SummarizeFrames(RunSummary& summary) {
  std::vector<double> ba_medians, edge_medians, latencies;
  double tracked_points = 0, plane_residuals = 0;
  int bas = 0;
  auto add_crease_check = [&](const CreaseCheckStats& check) {
    ++summary.crease_keyframes;
    summary.mean_visible_creases += check.visible_creases;
    summary.mean_confirmed_creases += check.confirmed_creases;
    if (check.median_edge_px) edge_medians.push_back(*check.median_edge_px);
  };
  for (const FrameStats& s : summary.stats) {
    if (s.latency_ms) latencies.push_back(*s.latency_ms);
    ++summary.frames;
    summary.skipped += s.skipped ? 1 : 0;
    summary.lost += s.state == TrackingState::kLost ? 1 : 0;
    summary.tracked += (!s.skipped && s.state != TrackingState::kLost) ? 1 : 0;
    summary.keyframes += s.keyframe ? 1 : 0;
    tracked_points += s.tracked_points;
    if (s.ba_median_reprojection_px) ba_medians.push_back(*s.ba_median_reprojection_px);
    if (s.planes_disabled) summary.planes_disabled = *s.planes_disabled;
    if (s.depth_points) {
      ++summary.depth_frames;
      summary.mean_depth_points += *s.depth_points;
    }
    summary.depth_refused += s.depth_refused ? 1 : 0;
    if (s.consensus_correction) ++summary.consensus_corrections;
    if (s.crease_check) add_crease_check(*s.crease_check);
    if (s.ba_plane_residuals) {
      plane_residuals += *s.ba_plane_residuals;
      ++bas;
    }
  }
  if (bas > 0) summary.mean_ba_plane_residuals = plane_residuals / bas;
  if (summary.depth_frames > 0) summary.mean_depth_points /= summary.depth_frames;
  if (summary.crease_keyframes > 0) {
    summary.mean_visible_creases /= summary.crease_keyframes;
    summary.mean_confirmed_creases /= summary.crease_keyframes;
  }
  if (!edge_medians.empty()) {
    std::sort(edge_medians.begin(), edge_medians.end());
    summary.median_edge_px = edge_medians[edge_medians.size() / 2];
  }
  if (summary.frames > 0) summary.mean_tracked_points = tracked_points / summary.frames;
  if (!latencies.empty()) {
    std::sort(latencies.begin(), latencies.end());
    summary.latency_p50_ms = Percentile(latencies, 0.5);
    summary.latency_p99_ms = Percentile(latencies, 0.99);
    summary.latency_max_ms = latencies.back();
  }
  if (!ba_medians.empty()) {
    std::sort(ba_medians.begin(), ba_medians.end());
    summary.median_ba_reprojection_px = ba_medians[ba_medians.size() / 2];
  }
}

// The run's plane map (none without --planes), with the world frame it sets said in the log.
std::optional<PlaneMap> ReadRunPlaneMap(const RunOptions& run) {
  std::optional<PlaneMap> plane_map;
  if (run.planes_path) {
    plane_map = ReadPlaneMap(*run.planes_path);
    if (plane_map->planes.empty()) {
      spdlog::warn("{}: the plane map has no planes; the run is visual odometry only",
                   run.planes_path->string());
    }
    if (plane_map->sigma_defaulted) {
      spdlog::warn(
          "{}: no per-plane sigma (written before `map planes` wrote them); every plane gets the "
          "default, {} m in offset and {:.2f} deg in normal (docs/map.md, \"Plane uncertainty\"); "
          "regenerate it with `planeloc map planes` for the map's own",
          run.planes_path->string(), kDefaultPlaneOffsetSigma,
          kDefaultPlaneNormalSigma * 180.0 / std::numbers::pi);
    }
    // The plane map's frame is the world frame of the run: the initial pose must be given in it.
    const PlaneMapFrame& frame = plane_map->frame;
    const Eigen::Vector3d& t = run.world_from_cam_initial.translation;
    if (frame.known()) {
      spdlog::info(
          "run: world frame = the plane map's frame '{}' (map {}, up [{:.3f}, {:.3f}, {:.3f}] "
          "{}); initial camera position in it: [{:.3f}, {:.3f}, {:.3f}]",
          frame.name, frame.map_file, frame.up.x(), frame.up.y(), frame.up.z(), frame.up_source,
          t.x(), t.y(), t.z());
    } else {
      spdlog::info(
          "run: world frame = the frame of {} (written before frames were recorded; assumed to "
          "be the frame of the initial pose); initial camera position in it: [{:.3f}, {:.3f}, "
          "{:.3f}]",
          run.planes_path->string(), t.x(), t.y(), t.z());
    }
  }
  if (plane_map) {
    const std::string warning =
        StartPriorWarning(*plane_map, run.world_from_cam_initial.translation, run.start_prior);
    if (!warning.empty()) spdlog::warn("{}", warning);
  }
  return plane_map;
}

// Tracks frames [0, total) of the sequence, writing each pose and stats line as it comes.
void TrackFrames(const StereoSource& sequence, std::size_t total,
                 const EffectiveSettings& effective, const std::string& calibration, bool realtime,
                 Tracker& tracker, TrajectoryWriter& writer, std::optional<OutputFile>& stats_out,
                 std::optional<ProgressBar>& progress, RunObserver* observer,
                 MapCloudCoverageCheck* coverage, RunSummary& summary) {
  // Real-time replay: frame i arrives at its camera time after the first frame's.
  using Clock = std::chrono::steady_clock;
  const Clock::time_point replay_start = Clock::now();
  auto arrival = [&](std::size_t i) {
    const double seconds = std::max(0.0, sequence.timestamp(i) - sequence.timestamp(0));
    return replay_start +
           std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
  };
  // The next frames are decoded, rectified and their features extracted and matched while frame
  // i is tracked: none of it depends on the tracker's state, and on 2 cores it otherwise sits on
  // the frame path while tracking, the local map and the keyframe's crease check run on one core.
  // The result does not depend on it (the features are the same and are tracked in order); an
  // error is raised at its own frame, as without the prefetch.
  struct LoadedFrame {
    std::optional<StereoFeatures> features;
    double ms_extract = 0;
    std::exception_ptr error;
  };
  auto load = [&](std::size_t i) {
    LoadedFrame loaded;
    if (!sequence.HasFrame(i)) return loaded;
    try {
      StereoPair pair = sequence.LoadStereoPair(i);
      if (effective.rectifier) pair = effective.rectifier->Rectify(pair);
      const auto extract_start = std::chrono::steady_clock::now();
      loaded.features = tracker.ExtractFeatures(pair.left, pair.right);
      loaded.ms_extract = std::chrono::duration<double, std::milli>(
                              std::chrono::steady_clock::now() - extract_start)
                              .count();
    } catch (...) {
      loaded.features.reset();
      loaded.error = std::current_exception();
    }
    return loaded;
  };
  // Two frames ahead: frame i + 1's decoding starts with a serial step (two PNGs), during which
  // a thread that finished tracking frame i had nothing to help with; frame i + 2's work fills
  // that gap (measured: docs/bench-tracking.md). Slot i % kFramesAhead holds frame i.
  constexpr std::size_t kFramesAhead = 2;
  std::array<LoadedFrame, kFramesAhead> ahead;
  // After `ahead`: on an exception each group waits for the task writing its slot.
  std::array<tbb::task_group, kFramesAhead> prefetch;
  CalibrationSpeedCheck speed_check(calibration);
  // Real-time replay: a frame's load starts only once it has arrived (a live camera has not
  // delivered it before). The wait is here, never inside a task: a thread waiting for one slot
  // may run the other slot's task, and would sleep in it.
  std::size_t launched = 0;                       // frames [0, launched) have their load started
  auto launch_arrived = [&](std::size_t up_to) {  // starts the loads of frames < up_to that arrived
    while (launched < std::min(up_to, total) && (!realtime || Clock::now() >= arrival(launched))) {
      const std::size_t j = launched++;
      const std::size_t slot = j % kFramesAhead;
      prefetch[slot].run([&ahead, &load, slot, j] { ahead[slot] = load(j); });
    }
  };
  launch_arrived(kFramesAhead);
  for (std::size_t i = 0; i < total; ++i) {
    const std::size_t slot = i % kFramesAhead;
    if (launched == i) {  // real time: frame i has not arrived yet
      std::this_thread::sleep_until(arrival(i));
      launch_arrived(i + 1);
    }
    prefetch[slot].wait();
    LoadedFrame current = std::move(ahead[slot]);
    ahead[slot] = LoadedFrame{};
    launch_arrived(i + 1 + kFramesAhead);
    std::optional<StereoFeatures> features = std::move(current.features);
    if (!sequence.HasFrame(i)) {
      spdlog::warn("frame {}: image missing ({}), pose from the motion model", i,
                   sequence.MissingFrame(i));
    } else if (current.error) {
      try {
        std::rethrow_exception(current.error);
      } catch (const InputError& e) {
        // Frame 0 sets the initial pose and the scale: without it the whole trajectory is wrong.
        if (i == 0) throw;
        spdlog::warn("frame {}: {}; frame skipped, pose from the motion model", i, e.what());
      }
    }
    const TrackResult result =
        features
            ? tracker.TrackFeatures(std::move(*features), sequence.timestamp(i), current.ms_extract)
            : tracker.SkipFrame(sequence.timestamp(i));
    writer.Write(sequence.timestamp(i), result.world_from_cam);
    speed_check.Add(sequence, i, result.world_from_cam);
    FrameStats stats = result.stats;
    if (realtime) {
      stats.latency_ms =
          std::chrono::duration<double, std::milli>(Clock::now() - arrival(i)).count();
    }
    if (stats_out) stats_out->Write(stats.ToJson() + '\n');
    if (coverage) coverage->Add(stats);
    summary.stats.push_back(stats);
    summary.world_from_cam.push_back(result.world_from_cam);
    if (progress) progress->Update(i + 1);
    if (observer) {
      observer->OnFrame(stats, result.world_from_cam);
      if (observer->WantsFrameView()) {
        observer->OnFrameView(tracker.DescribeLastFrame(observer->WantsPlaneUpdates()));
      }
    }
    launch_arrived(i + 1 + kFramesAhead);
  }
}

}  // namespace

RunSummary RunSequence(const RunOptions& run) {
  RunSummary summary;
  // Read first: a bad plane map fails before any work.
  const std::optional<PlaneMap> plane_map = ReadRunPlaneMap(run);
  if (plane_map) summary.planes = static_cast<int>(plane_map->planes.size());
  std::optional<SettingsFile> settings = ReadSettings(run);
  // The map cloud too, with the settings' voxel size: a missing or empty cloud fails before any
  // work.
  std::shared_ptr<const MapCloudIndex> map_cloud;
  if (run.map_cloud_path) {
    PointCloudReadOptions read;
    read.voxel_size =
        settings ? settings->options.depth.voxel_size : DepthPriorOptions{}.voxel_size;
    map_cloud = std::make_shared<MapCloudIndex>(ReadPointCloud(*run.map_cloud_path, read).points);
    summary.map_cloud_points = map_cloud->size();
    spdlog::info("{}: {} points after the {:.2f} m voxel filter (DepthPrior.voxelSize)",
                 run.map_cloud_path->string(), map_cloud->size(), read.voxel_size);
  }
  std::shared_ptr<const StereoSource> source = run.source;
  if (!source && AslSequence::IsAslFolder(run.sequence)) {
    source = std::make_shared<AslSequence>(AslSequence::Open(run.sequence));
  }
  if (dynamic_cast<const AslSequence*>(source.get())) {
    spdlog::info("{}: ASL/EuRoC layout, {} stereo frames, raw pairs rectified on load",
                 source->name(), source->size());
  }
  if (!source)
    source = std::make_shared<KittiSequence>(KittiSequence::Open(run.sequence, run.cameras));
  const StereoSource& sequence = *source;
  CheckInput(sequence.size() > 0, sequence.name(), 0, "the sequence has no frames",
             run.source ? "pass a source with stereo frames"
                        : "point --sequence at a KITTI odometry sequence, a raw drive or an "
                          "ASL/EuRoC mav0 folder");
  const EffectiveSettings effective = Effective(run, std::move(settings), sequence.camera());
  summary.options = effective.options;
  summary.camera = effective.camera;
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(summary.options.num_threads));
  if (run.write_effective_settings) {
    WriteTrackerSettings(run.trajectory_path.string() + ".config.yaml", summary.options,
                         summary.camera, effective.calibration_from_settings,
                         effective.rectifier.get());
  }
  // The planes.json the updates refer to, hashed before the run (`map update` checks it).
  std::string planes_hash;
  if (run.map_update_path) {
    CheckInput(plane_map.has_value(), run.map_update_path->string(), 0,
               "a map update needs the plane map it updates", "add --planes planes.json");
    planes_hash = FileHash(*run.planes_path);
  }
  TrajectoryWriter writer(run.trajectory_path, run.format);
  std::optional<OutputFile> stats_out;
  if (run.stats_path) stats_out.emplace(*run.stats_path, OutputFile::Mode::kIncremental);
  const std::size_t total =
      run.max_frames > 0 ? std::min<std::size_t>(run.max_frames, sequence.size()) : sequence.size();
  Tracker tracker(summary.camera, summary.options, run.world_from_cam_initial,
                  plane_map ? &*plane_map : nullptr, run.start_prior, map_cloud);
  std::optional<ProgressBar> progress;
  if (run.show_progress) progress.emplace("run", total, "frames");
  const auto start = std::chrono::steady_clock::now();
  const std::string calibration = effective.calibration_from_settings ? run.settings_path->string()
                                                                      : sequence.calibration_name();
  if (run.observer) {
    run.observer->OnStart(summary.camera, static_cast<int>(total),
                          plane_map ? &*plane_map : nullptr);
  }
  std::optional<MapCloudCoverageCheck> coverage;
  const DepthPriorOptions& depth = summary.options.depth;
  if (run.map_cloud_path && (depth.frame_refinement || (depth.window_surfaces && !plane_map))) {
    coverage.emplace(run.map_cloud_path->string(), !depth.frame_refinement);
  }
  TrackFrames(sequence, total, effective, calibration, run.realtime, tracker, writer, stats_out,
              progress, run.observer.get(), coverage ? &*coverage : nullptr, summary);
  tracker.Finish();
  writer.Close();
  if (run.final_trajectory_path) {
    const std::vector<Rigid3d> final_poses =
        ReexpressBeforeLock(summary.world_from_cam, summary.stats, tracker.lock_events());
    TrajectoryWriter final_writer(*run.final_trajectory_path, run.format);
    for (std::size_t i = 0; i < final_poses.size(); ++i) {
      final_writer.Write(sequence.timestamp(i), final_poses[i]);
    }
    final_writer.Close();
  }
  if (stats_out) stats_out->Commit();
  if (progress) progress->Finish();
  summary.ba = tracker.ba_counts();
  summary.lock_events = tracker.lock_events();
  if (plane_map) summary.final_map_lock = MapLockName(tracker.map_lock());
  summary.lock_attempts = tracker.lock_attempts();
  const std::map<std::string, int> refusals = tracker.lock_refusals();
  summary.lock_refusals.assign(refusals.begin(), refusals.end());
  std::stable_sort(summary.lock_refusals.begin(), summary.lock_refusals.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  SummarizeFrames(summary);
  if (run.map_update_path && plane_map && tracker.plane_evidence()) {
    MapUpdates updates;
    updates.planes_path = *run.planes_path;
    updates.planes_hash = planes_hash;
    updates.planes_count = static_cast<int>(plane_map->planes.size());
    updates.frame_name = plane_map->frame.known() ? plane_map->frame.name : "";
    updates.sequence = run.source ? sequence.name() : run.sequence.string();
    updates.frames = summary.frames;
    updates.trajectory = run.trajectory_path.string();
    updates.planes = tracker.plane_evidence()->Summarize();
    for (const PlaneUpdate& plane : updates.planes)
      ++summary.map_update_counts[ToString(plane.status)];
    WriteMapUpdates(*run.map_update_path, updates);
    spdlog::info(
        "{}: planes unseen {}, confirmed {}, corrected {}, contradicted {} (docs/map-update.md)",
        run.map_update_path->string(), summary.map_update_counts["unseen"],
        summary.map_update_counts["confirmed"], summary.map_update_counts["corrected"],
        summary.map_update_counts["contradicted"]);
  }
  if (run.observer) run.observer->OnFinish(summary);
  if (run.summary_path) {
    std::ofstream out(*run.summary_path);
    out << summary.ToJson() << '\n';
    CheckInput(out.good(), run.summary_path->string(), 0, "cannot write the run summary",
               "check that the folder exists and is writable");
  }
  if (run.report_dir) {
    WriteReportFolder(run, summary, sequence, effective, plane_map ? &*plane_map : nullptr);
  }
  return summary;
}

std::string RunSummary::ToJson() const {
  std::string json = fmt::format(
      "{{\"frames\":{},\"tracked\":{},\"lost\":{},\"skipped\":{},\"keyframes\":{},"
      "\"mean_tracked_points\":{:.1f},\"median_ba_reprojection_px\":{:.4f},\"planes\":{},"
      "\"mean_ba_plane_residuals\":{:.1f},\"planes_disabled\":{},\"consensus_corrections\":{},"
      "\"seconds\":{:.3f},\"final_map_lock\":\"{}\",\"lock_events\":{},\"local_ba\":{}}}",
      frames, tracked, lost, skipped, keyframes, mean_tracked_points, median_ba_reprojection_px,
      planes, mean_ba_plane_residuals, planes_disabled, consensus_corrections, seconds,
      final_map_lock, lock_events.size(), ba.ToJson());
  if (!map_update_counts.empty()) {
    json.pop_back();
    json += ",\"map_update\":{";
    bool first = true;
    for (const auto& [status, count] : map_update_counts) {
      json += fmt::format("{}\"{}\":{}", first ? "" : ",", status, count);
      first = false;
    }
    json += "}}";
  }
  if (map_cloud_points > 0) {
    json.pop_back();
    json += fmt::format(
        ",\"map_cloud_points\":{},\"depth_frames\":{},\"mean_depth_points\":{:.1f},"
        "\"depth_refused\":{}}}",
        map_cloud_points, depth_frames, mean_depth_points, depth_refused);
  }
  if (!final_map_lock.empty()) {
    json.pop_back();
    json += fmt::format(",\"lock_attempts\":{},\"lock_refusals\":{{", lock_attempts);
    for (std::size_t i = 0; i < lock_refusals.size(); ++i) {
      json += fmt::format("{}{}:{}", i ? "," : "", nlohmann::json(lock_refusals[i].first).dump(),
                          lock_refusals[i].second);
    }
    json += "}}";
  }
  if (latency_p50_ms) {
    json.pop_back();  // the closing brace
    json += fmt::format(",\"latency_ms\":{{\"p50\":{:.2f},\"p99\":{:.2f},\"max\":{:.2f}}}}}",
                        *latency_p50_ms, *latency_p99_ms, *latency_max_ms);
  }
  return json;
}

}  // namespace planeloc
