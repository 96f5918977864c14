#include "planeloc/tracking/run_sequence.h"

#include <spdlog/spdlog.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "planeloc/io/plane_map.h"
#include "planeloc/util/error.h"
#include "planeloc/util/progress.h"

namespace planeloc {
namespace {

std::vector<double> ParseNumbers(const std::string& text) {
  std::istringstream in(text);
  std::vector<double> numbers;
  std::string token;
  while (in >> token) {
    try {
      std::size_t used = 0;
      numbers.push_back(std::stod(token, &used));
      if (used != token.size()) return {};
    } catch (const std::exception&) {
      return {};
    }
  }
  return numbers;
}

Rigid3d FromTwelve(const std::vector<double>& v) {
  Eigen::Matrix<double, 3, 4> m;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) m(r, c) = v[r * 4 + c];
  }
  return Rigid3d::FromMatrix3x4(m);
}

TrackerOptions EffectiveOptions(const RunOptions& run, const StereoCamera& camera) {
  TrackerOptions options;
  if (run.settings_path) {
    SettingsFile file = LoadTrackerSettings(*run.settings_path, options, camera);
    for (const auto& warning : file.warnings) {
      spdlog::warn("{}: {}", run.settings_path->string(), warning);
    }
    options = file.options;
  }
  if (run.deterministic) options.deterministic = true;
  if (run.threads > 0) options.num_threads = run.threads;
  if (options.deterministic)
    options.ba.num_threads = 1;
  else
    options.ba.num_threads = options.num_threads;
  options.Check();
  return options;
}

}  // namespace

Rigid3d ParsePose12(const std::string& text) {
  const std::vector<double> v = ParseNumbers(text);
  CheckInput(v.size() == 12, "", 0,
             "--init-pose needs 12 numbers (row-major 3x4 world_from_cam), got \"" + text + "\"",
             "pass e.g. --init-pose \"1 0 0 0 0 1 0 0 0 0 1 0\"");
  return FromTwelve(v);
}

Rigid3d ReadFirstPose(const std::filesystem::path& path) {
  std::ifstream in(path);
  CheckInput(in.good(), path.string(), 0, "cannot open the pose file",
             "check the path given to --init-pose-from");
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    const std::vector<double> v = ParseNumbers(line);
    if (v.size() == 12) return FromTwelve(v);
    if (v.size() == 8) {
      const Eigen::Quaterniond q(v[7], v[4], v[5], v[6]);
      CheckInput(q.norm() > 1e-9, path.string(), number, "zero quaternion",
                 "write a valid TUM line: t tx ty tz qx qy qz qw");
      return Rigid3d(q.normalized(), Eigen::Vector3d(v[1], v[2], v[3]));
    }
    throw InputError(path.string(), number,
                     "expected a KITTI pose (12 numbers) or a TUM pose (8 numbers)",
                     "pass a KITTI or TUM trajectory file");
  }
  throw InputError(path.string(), 0, "the pose file holds no pose", "pass a non-empty file");
}

RunSummary RunSequence(const RunOptions& run) {
  RunSummary summary;
  std::optional<PlaneMap> plane_map;  // read first: a bad plane map fails before any work
  if (run.planes_path) {
    plane_map = ReadPlaneMap(*run.planes_path);
    summary.planes = static_cast<int>(plane_map->planes.size());
    if (plane_map->planes.empty()) {
      spdlog::warn("{}: the plane map has no planes; the run is visual odometry only",
                   run.planes_path->string());
    }
  }
  const KittiSequence sequence = KittiSequence::Open(run.sequence, run.cameras);
  CheckInput(sequence.size() > 0, run.sequence.string(), 0, "the sequence has no frames",
             "point --sequence at a KITTI odometry sequence or raw drive folder");
  summary.options = EffectiveOptions(run, sequence.camera());
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism,
                              static_cast<std::size_t>(summary.options.num_threads));
  if (run.write_effective_settings) {
    WriteTrackerSettings(run.trajectory_path.string() + ".config.yaml", summary.options,
                         sequence.camera());
  }
  TrajectoryWriter writer(run.trajectory_path, run.format);
  std::optional<std::ofstream> stats_out;
  if (run.stats_path) {
    stats_out.emplace(*run.stats_path);
    CheckInput(stats_out->good(), run.stats_path->string(), 0, "cannot write the stats file",
               "check that the folder exists and is writable");
  }
  const std::size_t total =
      run.max_frames > 0 ? std::min<std::size_t>(run.max_frames, sequence.size()) : sequence.size();
  Tracker tracker(sequence.camera(), summary.options, run.world_from_cam_initial,
                  plane_map ? &*plane_map : nullptr);
  std::optional<ProgressBar> progress;
  if (run.show_progress) progress.emplace("run", total, "frames");
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < total; ++i) {
    std::optional<StereoPair> pair;
    if (!sequence.HasFrame(i)) {
      const bool has_left = std::filesystem::is_regular_file(sequence.left_image_path(i));
      spdlog::warn(
          "frame {}: image missing ({}), pose from the motion model", i,
          (has_left ? sequence.right_image_path(i) : sequence.left_image_path(i)).string());
    } else {
      try {
        pair = sequence.LoadStereoPair(i);
      } catch (const InputError& e) {
        spdlog::warn("frame {}: {}; pose from the motion model", i, e.what());
      }
    }
    const TrackResult result = pair ? tracker.Track(pair->left, pair->right, sequence.timestamp(i))
                                    : tracker.SkipFrame(sequence.timestamp(i));
    writer.Write(sequence.timestamp(i), result.world_from_cam);
    if (stats_out) *stats_out << result.stats.ToJson() << '\n' << std::flush;
    summary.stats.push_back(result.stats);
    summary.world_from_cam.push_back(result.world_from_cam);
    if (progress) progress->Update(i + 1);
  }
  tracker.Finish();
  if (progress) progress->Finish();
  summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::vector<double> ba_medians;
  double tracked_points = 0, plane_residuals = 0;
  int bas = 0;
  for (const FrameStats& s : summary.stats) {
    ++summary.frames;
    summary.skipped += s.skipped ? 1 : 0;
    summary.lost += s.state == TrackingState::kLost ? 1 : 0;
    summary.tracked += (!s.skipped && s.state != TrackingState::kLost) ? 1 : 0;
    summary.keyframes += s.keyframe ? 1 : 0;
    tracked_points += s.tracked_points;
    if (s.ba_median_reprojection_px) ba_medians.push_back(*s.ba_median_reprojection_px);
    if (s.planes_disabled) summary.planes_disabled = *s.planes_disabled;
    if (s.ba_plane_residuals) {
      plane_residuals += *s.ba_plane_residuals;
      ++bas;
    }
  }
  if (bas > 0) summary.mean_ba_plane_residuals = plane_residuals / bas;
  if (summary.frames > 0) summary.mean_tracked_points = tracked_points / summary.frames;
  if (!ba_medians.empty()) {
    std::sort(ba_medians.begin(), ba_medians.end());
    summary.median_ba_reprojection_px = ba_medians[ba_medians.size() / 2];
  }
  return summary;
}

}  // namespace planeloc
