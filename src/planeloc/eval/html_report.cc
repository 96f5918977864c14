#include "planeloc/eval/html_report.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <vector>

#include "planeloc/eval/ape.h"
#include "planeloc/eval/html_page_kit.h"
#include "planeloc/eval/kitti_drift.h"
#include "planeloc/eval/pose_path.h"
#include "planeloc/eval/statistics.h"
#include "planeloc/io/map_updates.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

#include "planeloc/eval/html_report_page.inc"

std::optional<std::string> ReadIfExists(const fs::path& path) {
  std::error_code error;
  if (!fs::is_regular_file(path, error)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

// Four decimals keep the page small (positions in metres to 0.1 mm).
double Round4(double value) { return std::isfinite(value) ? std::round(value * 1e4) / 1e4 : 0.0; }

json PositionsJson(const PoseMatrices& poses) {
  json out = json::array();
  for (const Eigen::Matrix4d& pose : poses) {
    out.push_back({Round4(pose(0, 3)), Round4(pose(1, 3)), Round4(pose(2, 3))});
  }
  return out;
}

json Rounded(const std::vector<double>& values) {
  json out = json::array();
  for (double v : values) out.push_back(Round4(v));
  return out;
}

// KITTI (12 numbers a line) or TUM (8) by the first pose line, as `run --init-pose-from` does.
TrajectoryFormat DetectFormat(const fs::path& path) {
  std::ifstream in(path);
  CheckInput(static_cast<bool>(in), path.string(), 0, "--gt: cannot read the pose file",
             "pass a KITTI or TUM pose file that exists");
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    int count = 0;
    std::string field;
    while (fields >> field) ++count;
    if (count == 0) continue;
    return count == 8 ? TrajectoryFormat::kTum : TrajectoryFormat::kKitti;
  }
  throw InputError(path.string(), "the pose file holds no pose", "pass a non-empty pose file");
}

PoseMatrices ReadPoses(const fs::path& path, TrajectoryFormat format) {
  if (format == TrajectoryFormat::kKitti) return ToPoseMatrices(ReadKittiPoseMatrices(path));
  return ToPoseMatrices(ReadTumTrajectory(path));
}

json StatsJson(const ErrorStatistics& s) {
  return {{"mean", s.mean}, {"rmse", s.rmse},     {"std", s.std},
          {"max", s.max},   {"median", s.median}, {"n", s.n}};
}

struct Ground {
  PoseMatrices poses;
  std::vector<double> distance;  // along the GT path, metres
};

// Errors of `run` against the GT: per frame 3-D, 2-D (horizontal) and per axis, and their
// statistics; KITTI drift when the path is long enough for a segment.
void AddErrors(const Ground& gt, const PoseMatrices& estimate, const Eigen::Vector3d& up,
               json* run) {
  const std::size_t n = std::min(gt.poses.size(), estimate.size());
  if (n == 0) return;
  const PoseMatrices reference(gt.poses.begin(), gt.poses.begin() + n);
  const PoseMatrices est(estimate.begin(), estimate.begin() + n);
  std::vector<double> ate3, ate2, lateral, height, along;
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d g = reference[i].block<3, 1>(0, 3);
    const Eigen::Vector3d e = est[i].block<3, 1>(0, 3) - g;
    // Central difference of the GT; kept from the previous frame while the vehicle stands.
    const std::size_t a = i > 0 ? i - 1 : i, b = std::min(i + 1, n - 1);
    const Eigen::Vector3d step = reference[b].block<3, 1>(0, 3) - reference[a].block<3, 1>(0, 3);
    if (step.norm() > 1e-6) direction = step;
    const AxisErrors axes = DecomposeError(e, direction, up);
    ate3.push_back(e.norm());
    ate2.push_back(std::hypot(axes.lateral, axes.along));
    lateral.push_back(axes.lateral);
    height.push_back(axes.height);
    along.push_back(axes.along);
  }
  (*run)["errors"] = {{"ate3d", Rounded(ate3)},      {"ate2d", Rounded(ate2)},
                      {"lateral", Rounded(lateral)}, {"height", Rounded(height)},
                      {"along", Rounded(along)},     {"paired", n}};
  json stats = {{"ate3d", StatsJson(ComputeStatistics(ate3))},
                {"ate2d", StatsJson(ComputeStatistics(ate2))},
                {"kitti_drift", nullptr}};
  try {
    const KittiDriftResult drift = ComputeKittiDrift(reference, est);
    stats["kitti_drift"] = {{"t_rel_percent", drift.translation_percent},
                            {"r_rel_deg_per_100m", drift.rotation_deg_per_100m},
                            {"segments", drift.segments.size()}};
  } catch (const InputError&) {
    // The path is shorter than the shortest segment (100 m): no drift, shown as "n/a".
  }
  (*run)["error_stats"] = stats;
}

// `states`: plane id -> its status in the run's map_update.json (none: no "state" field).
json PlanesJson(const PlaneMap& map, const std::map<int, std::string>& states) {
  json planes = json::array();
  for (const MapPlane& plane : map.planes) {
    if (plane.polygon.size() < 3) continue;
    json polygon = json::array();
    for (const Eigen::Vector3d& p : plane.polygon) {
      polygon.push_back({Round4(p.x()), Round4(p.y()), Round4(p.z())});
    }
    planes.push_back({{"id", plane.id},
                      {"kind", plane.kind.empty() ? "other" : plane.kind},
                      {"area", plane.area},
                      {"polygon", polygon}});
    if (const auto state = states.find(plane.id); state != states.end()) {
      planes.back()["state"] = state->second;
    }
  }
  return planes;
}

struct LoadedRun {
  json data;
  fs::path trajectory_path;
  PoseMatrices poses;
  std::optional<PlaneMap> planes;
  std::map<int, std::string> plane_states;  // from map_update.json (run --map-update)
  TrajectoryFormat format = TrajectoryFormat::kKitti;
};

// One line of stats.jsonl into the series the page plots. Throws json::exception for a field
// of the wrong type.
void AddStatsLine(const json& s, json* frames, json* timing, json* kf, json* ba, json* lock) {
  const int frame = s.at("frame").get<int>();
  frames->push_back(frame);
  const json ms = s.value("ms", json::object());
  for (const char* stage : {"extract", "track", "local_map", "ba"}) {
    (*timing)[stage].push_back(Round4(ms.value(stage, 0.0)));
  }
  if (s.value("keyframe", false)) {
    (*kf)["frame"].push_back(frame);
    (*kf)["tracked_points"].push_back(s.value("tracked_points", 0));
    (*kf)["planes_disabled"].push_back(
        s.contains("planes_disabled") ? json(s["planes_disabled"].get<int>()) : json(nullptr));
  }
  if (s.contains("ba_plane_residuals")) {
    (*ba)["frame"].push_back(frame);
    (*ba)["plane_residuals"].push_back(s["ba_plane_residuals"].get<int>());
  }
  lock->push_back(s.value("map_lock", ""));
}

// run.json (optional): the run's mode, sequence and trajectory format.
json ReadRunMeta(const fs::path& dir) {
  json meta = json::object();
  if (std::optional<std::string> text = ReadIfExists(dir / "run.json")) {
    meta = json::parse(*text, nullptr, /*allow_exceptions=*/false);
    CheckInput(meta.is_object(), (dir / "run.json").string(), 0, "not a JSON object",
               "re-run `planeloc run --report-dir` to rewrite the folder");
    for (const char* key : {"mode", "sequence", "format"}) {
      CheckInput(!meta.contains(key) || meta[key].is_string(), (dir / "run.json").string(), 0,
                 fmt::format("\"{}\" is not a string", key),
                 "re-run `planeloc run --report-dir` to rewrite the folder");
    }
  }
  return meta;
}

// Per-frame stats (stats.jsonl, optional) into `out`: timing per stage, keyframes and what they
// tracked, map lock.
void AddStatsSeries(const fs::path& dir, json& out) {
  json timing = {{"extract", json::array()},
                 {"track", json::array()},
                 {"local_map", json::array()},
                 {"ba", json::array()}};
  json kf = {{"frame", json::array()},
             {"tracked_points", json::array()},
             {"planes_disabled", json::array()}};
  json ba = {{"frame", json::array()}, {"plane_residuals", json::array()}};
  json lock = json::array();
  json frames = json::array();
  if (std::optional<std::string> text = ReadIfExists(dir / "stats.jsonl")) {
    std::istringstream lines(*text);
    std::string line;
    int number = 0;
    while (std::getline(lines, line)) {
      ++number;
      if (line.empty()) continue;
      const json s = json::parse(line, nullptr, /*allow_exceptions=*/false);
      CheckInput(s.is_object() && s.contains("frame"), (dir / "stats.jsonl").string(), number,
                 "not a stats line of `planeloc run`",
                 "re-run `planeloc run --report-dir` to rewrite the folder");
      try {
        AddStatsLine(s, &frames, &timing, &kf, &ba, &lock);
      } catch (const json::exception& e) {
        throw InputError((dir / "stats.jsonl").string(), number,
                         fmt::format("a field has the wrong type ({})", e.what()),
                         "re-run `planeloc run --report-dir` to rewrite the folder");
      }
    }
  }
  bool any_lock = false;
  for (const json& state : lock) any_lock = any_lock || !state.get<std::string>().empty();
  out["frames"] = frames;
  out["timing"] = timing;
  out["keyframes"] = kf;
  out["ba"] = ba;
  out["map_lock"] = any_lock ? lock : json(nullptr);
}

// The keyframe overlays (keyframes/*.png|jpg), by name, embedded as base64.
json KeyframeImages(const fs::path& dir) {
  std::error_code error;
  json images = json::array();
  std::vector<fs::path> files;
  if (fs::is_directory(dir / "keyframes", error)) {
    for (const auto& entry : fs::directory_iterator(dir / "keyframes", error)) {
      const std::string extension = entry.path().extension().string();
      if (extension == ".png" || extension == ".jpg") files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  for (const fs::path& file : files) {
    const std::optional<std::string> bytes = ReadIfExists(file);
    if (!bytes) continue;
    images.push_back({{"name", file.stem().string()},
                      {"mime", file.extension() == ".png" ? "image/png" : "image/jpeg"},
                      {"data", Base64(*bytes)}});
  }
  return images;
}

LoadedRun LoadRun(const fs::path& dir, const std::string& flag) {
  std::error_code error;
  CheckInput(fs::is_directory(dir, error), dir.string(), 0,
             fmt::format("{}: not a report folder", flag),
             "pass the folder given to `planeloc run --report-dir`");
  LoadedRun run;
  const json meta = ReadRunMeta(dir);
  if (meta.contains("format") && meta["format"].is_string()) {
    run.format = ParseTrajectoryFormat(meta["format"].get<std::string>());
  }
  const fs::path trajectory = dir / "trajectory.txt";
  CheckInput(fs::is_regular_file(trajectory, error), trajectory.string(), 0,
             fmt::format("{}: the report folder has no trajectory", flag),
             "pass a folder written by `planeloc run --report-dir`");
  run.poses = ReadPoses(trajectory, run.format);
  run.trajectory_path = trajectory;
  if (fs::is_regular_file(dir / "planes.json", error))
    run.planes = ReadPlaneMap(dir / "planes.json");
  if (run.planes && fs::is_regular_file(dir / "map_update.json", error)) {
    for (const PlaneUpdate& update : ReadMapUpdates(dir / "map_update.json").planes) {
      run.plane_states[update.id] = ToString(update.status);
    }
  }
  const std::string mode = meta.value("mode", run.planes ? "planes" : "vo");

  json& out = run.data;
  out["dir"] = dir.string();
  out["mode"] = mode;
  out["label"] = mode == "planes" ? "plane mode" : "VO (no planes)";
  out["sequence"] = meta.value("sequence", "");
  out["positions"] = PositionsJson(run.poses);

  AddStatsSeries(dir, out);
  out["summary"] = json::object();
  if (std::optional<std::string> text = ReadIfExists(dir / "summary.json")) {
    const json summary = json::parse(*text, nullptr, /*allow_exceptions=*/false);
    if (summary.is_object()) out["summary"] = summary;
  }
  out["settings"] = ReadIfExists(dir / "settings.yaml").value_or("");

  out["images"] = KeyframeImages(dir);
  return run;
}

}  // namespace

AxisErrors DecomposeError(const Eigen::Vector3d& error, const Eigen::Vector3d& direction,
                          const Eigen::Vector3d& up) {
  const Eigen::Vector3d u = up.normalized();
  AxisErrors axes;
  axes.height = error.dot(u);
  Eigen::Vector3d forward = direction - direction.dot(u) * u;
  if (forward.norm() < 1e-9) {
    // No horizontal motion known: any horizontal axis pair; call the whole rest lateral.
    axes.lateral = (error - axes.height * u).norm();
    return axes;
  }
  forward.normalize();
  axes.along = error.dot(forward);
  axes.lateral = error.dot(u.cross(forward));
  return axes;
}

std::string Base64(const std::string& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                       (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size()) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (i + 1 < bytes.size()) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

json BuildReportData(const HtmlReportOptions& options) {
  std::vector<LoadedRun> runs;
  runs.push_back(LoadRun(options.run_dir, "--run"));
  if (options.compare_dir) runs.push_back(LoadRun(*options.compare_dir, "--compare"));

  // The plane map: the first run's that has one. Its frame's "up" names the height axis; without
  // one, KITTI camera poses have y down and TUM files are usually z up.
  const PlaneMap* map = nullptr;
  const std::map<int, std::string>* states = nullptr;
  for (const LoadedRun& run : runs) {
    if (run.planes && !map) {
      map = &*run.planes;
      states = &run.plane_states;
    }
  }
  Eigen::Vector3d up = runs[0].format == TrajectoryFormat::kTum ? Eigen::Vector3d(0, 0, 1)
                                                                : Eigen::Vector3d(0, -1, 0);
  std::string up_source = "assumed from the trajectory format";
  if (map && map->frame.up.norm() > 0.5) {
    up = map->frame.up.normalized();
    up_source = "the plane map's frame";
  }

  json data;
  data["title"] = options.title;
  data["up"] = {up.x(), up.y(), up.z()};
  data["up_source"] = up_source;
  data["planes"] = map ? PlanesJson(*map, *states) : json::array();
  // Planes coloured by what the run learned about them (run --map-update) instead of their kind.
  data["plane_states"] = states != nullptr && !states->empty();
  data["gt"] = nullptr;
  std::optional<Ground> gt;
  if (options.gt_path) {
    gt.emplace();
    gt->poses = ReadPoses(*options.gt_path, DetectFormat(*options.gt_path));
    gt->distance = AccumulatedDistances(gt->poses);
    data["gt"] = {{"path", options.gt_path->string()},
                  {"positions", PositionsJson(gt->poses)},
                  {"distance", Rounded(gt->distance)}};
  }
  data["runs"] = json::array();
  for (LoadedRun& run : runs) {
    // Pose k of the run and of the GT are the same frame, as `planeloc eval` pairs them: a run
    // cut short, or the GT of other frames, would give an ATE over a different set of frames.
    CheckInput(!gt || run.poses.size() == gt->poses.size(), run.trajectory_path.string(), 0,
               fmt::format("{} poses against {} in the GT {}: the run and the GT must cover the "
                           "same frames (planeloc eval refuses the same pair)",
                           run.poses.size(), gt ? gt->poses.size() : 0,
                           options.gt_path ? options.gt_path->string() : ""),
               "pass the GT of the run's sequence (a run that stopped early has no report ATE; "
               "evaluate its frames with `planeloc eval` on a GT cut to them)");
    if (gt) AddErrors(*gt, run.poses, up, &run.data);
    data["runs"].push_back(std::move(run.data));
  }
  return data;
}

std::string RenderHtmlReport(const HtmlReportOptions& options) {
  const std::string three_js = ThreeJsScripts(options.three_js_dir);
  const json data = BuildReportData(options);
  std::string page;
  page.reserve(three_js.size() + (1 << 20));
  page += PageKitHead();
  page += "<title>" + HtmlEscape(options.title) + "</title>\n";
  page += PageKitStyle();
  page += "</head>\n";
  page += kPageBody;
  page += three_js;
  page += "<script type=\"application/json\" id=\"report-data\">" + JsonScriptSafe(data.dump()) +
          "</script>\n";
  page += "<script>\n";
  page += PageKitScript();
  page += kPageScript;
  page += "</script>\n</body>\n</html>\n";
  return page;
}

}  // namespace planeloc
