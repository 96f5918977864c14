#include "planeloc/sim/simulator.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include "planeloc/io/trajectory.h"
#include "planeloc/sim/raycast.h"
#include "planeloc/sim/render.h"
#include "planeloc/sim/room_sequence.h"
#include "planeloc/sim/shading.h"
#include "planeloc/sim/sim_output.h"
#include "planeloc/sim/street.h"
#include "planeloc/sim/texture.h"
#include "planeloc/sim/town.h"
#include "planeloc/util/error.h"
#include "planeloc/util/progress.h"
#include "planeloc/util/safe_file.h"

namespace planeloc::sim {
namespace {

namespace fs = std::filesystem;

constexpr double kRateHz = 10.0;
constexpr double kLaneOffset = -1.75;  // the vehicle keeps to the right lane
constexpr const char* kPresets = "tiny, small, kitti07-like, rural, room";

int PresetFrames(const std::string& preset) {
  if (preset == "tiny") return 60;
  if (preset == "small" || preset == "rural") return 300;
  return 1101;
}

// KITTI odometry sequence 07, `Tr:` of calib.txt (velodyne -> rectified camera 0).
Eigen::Matrix<double, 3, 4> Kitti07Tr() {
  Eigen::Matrix<double, 3, 4> tr;
  tr << -1.857739385241e-03, -9.999659513510e-01, -8.039975204516e-03, -4.784029760483e-03,
      -6.481465826011e-03, 8.051860151134e-03, -9.999466081774e-01, -7.337429464231e-02,
      9.999773098287e-01, -1.805528627661e-03, -6.496203536139e-03, -3.339968064433e-01;
  return tr;
}

// The io reader's checks (a line of 12 finite numbers, a rotation) with their line numbers.
std::vector<Rigid3d> ReadPoseFile(const fs::path& path) {
  std::vector<Rigid3d> poses = ReadKittiTrajectory(path).world_from_cam;
  CheckInput(poses.size() >= 2, path.string(), 0, "the trajectory has fewer than 2 poses",
             "pass a KITTI pose file with at least 2 lines");
  return poses;
}

// Street centre line along a driven path (positions in W): points >= 0.5 m apart, shifted left
// so the vehicle drives in the right lane, and extended 150 m straight at both ends.
StreetPath StreetAlong(const std::vector<Eigen::Vector2d>& driven,
                       const Eigen::Vector2d& heading0) {
  std::vector<Eigen::Vector2d> points;
  for (const auto& p : driven) {
    if (points.empty() || (p - points.back()).norm() >= 0.5) points.push_back(p);
  }
  if (points.size() < 3 || (points.back() - points.front()).norm() < 1.0) {
    points = {driven.front(), driven.front() + 1.0 * heading0};
  }
  const StreetPath lane(points, false);
  const Eigen::Vector2d t0 = lane.Tangent(0.0), t1 = lane.Tangent(lane.length());
  std::vector<Eigen::Vector2d> extended;
  for (int k = 300; k > 0; --k) extended.push_back(lane.points().front() - 0.5 * k * t0);
  extended.insert(extended.end(), lane.points().begin(), lane.points().end());
  for (int k = 1; k <= 300; ++k) extended.push_back(lane.points().back() + 0.5 * k * t1);
  return StreetPath(extended, false).Offset(-kLaneOffset);
}

// --trajectory: W has z along the normal of the plane fitted to the camera centres (KITTI-07 is
// a gently tilted plane), x along the first camera's forward direction, ground 1.65 m below.
void ScenarioFromPoseFile(const SimOptions& options, int frames, Scenario* out,
                          StreetPath* street) {
  std::vector<Rigid3d> file_poses = ReadPoseFile(options.trajectory_path);
  if (frames < static_cast<int>(file_poses.size()))
    file_poses.resize(static_cast<std::size_t>(frames));
  const Eigen::Matrix3d r0 = file_poses[0].RotationMatrix();
  Eigen::Vector3d up = -r0.col(1);
  double d = -up.dot(file_poses[0].translation);
  std::vector<Eigen::Vector3d> centres;
  for (const auto& p : file_poses) centres.push_back(p.translation);
  try {
    const Plane fitted = Plane::Fit(centres);
    if (fitted.normal.dot(up) > std::cos(0.2)) {  // trust the fit only when it is near level
      up = fitted.normal, d = fitted.d;
    } else if (fitted.normal.dot(up) < -std::cos(0.2)) {
      up = -fitted.normal, d = -fitted.d;
    }
  } catch (const std::invalid_argument&) {
    // Collinear centres (a straight drive): keep the first camera's up direction.
  }
  const Eigen::Vector3d x = (r0.col(2) - r0.col(2).dot(up) * up).normalized();
  const Eigen::Vector3d y = up.cross(x);
  Eigen::Matrix3d w_from_file;
  w_from_file << x.transpose(), y.transpose(), up.transpose();
  const Eigen::Vector3d p0 = file_poses[0].translation;
  const Rigid3d world_from_file(w_from_file, Eigen::Vector3d(-x.dot(p0), -y.dot(p0), d + 1.65));
  std::vector<Eigen::Vector2d> driven;
  for (const auto& p : file_poses) {
    out->world_from_cam.push_back(world_from_file * p);
    driven.push_back(out->world_from_cam.back().translation.head<2>());
  }
  *street = StreetAlong(driven, Eigen::Vector2d(1.0, 0.0));
}

void ScenarioFromPreset(const SimOptions& options, int frames, Scenario* out, StreetPath* street) {
  // Street beyond the last frame (12.5 m/s max); it depends on the preset's length, not on
  // --frames, so the first N frames of a run are the same for every N up to the preset's.
  const double extra = std::max(frames, PresetFrames(options.preset)) * 1.25 + 150.0;
  DriveOptions drive;
  drive.start_s = 80.0;
  if (options.preset == "tiny") {
    *street = StreetPath::FromCorners({{-80.0, 0.0}, {std::max(400.0, extra), 0.0}}, false, 0.0);
    drive.cruise_speed = 10.0;
  } else if (options.preset == "small") {
    *street = StreetPath::FromCorners({{-80.0, 0.0}, {150.0, 0.0}, {150.0, std::max(500.0, extra)}},
                                      false, 15.0);
    drive.cruise_speed = 9.0;
  } else if (options.preset == "rural") {
    // A country road with two long bends (radius 150 m), about 360 m driven at 12 m/s.
    *street = StreetPath::FromCorners(
        {{-80.0, 0.0}, {250.0, 0.0}, {500.0, 120.0}, {std::max(800.0, extra + 300.0), 120.0}},
        false, 150.0);
    drive.cruise_speed = 12.0;
  } else {
    // A ~710 m block loop with six ~90 degree turns (one to the right), like KITTI-07's size.
    *street = StreetPath::FromCorners(
        {{0, 0}, {230, 0}, {230, 70}, {120, 70}, {120, 140}, {0, 140}}, true, 12.0);
    drive.start_s = 20.0;
  }
  const StreetPath lane = street->Offset(kLaneOffset);
  if (street->closed()) {
    drive.cruise_speed = CruiseSpeedFor(lane, PresetFrames(options.preset), lane.length(), drive);
  }
  out->world_from_cam = DriveAlong(lane, frames, drive, HashCombine(options.seed, 2u));
}

// --changes: the town becomes the mapping-time world (LiDAR) and a changed one (cameras). A preset
// draws its change sites along the preset's whole drive, so they do not depend on --frames.
void ApplyChanges(const SimOptions& options, const StreetPath& street, Scenario* scenario) {
  std::vector<Rigid3d> drive = scenario->world_from_cam;
  const int preset_frames = PresetFrames(options.preset);
  if (options.trajectory_path.empty() && static_cast<int>(drive.size()) < preset_frames) {
    Scenario whole;
    StreetPath same_street;
    ScenarioFromPreset(options, preset_frames, &whole, &same_street);
    drive = std::move(whole.world_from_cam);
  }
  std::vector<Eigen::Vector3d> camera_centres;
  for (const Rigid3d& pose : drive) camera_centres.push_back(pose.translation);
  ChangedWorld changed =
      ApplyWorldChanges(scenario->world, street, camera_centres, options.changes, options.seed);
  scenario->world = std::move(changed.now);
  scenario->mapping_world = std::move(changed.at_mapping);
  scenario->plane_changes = std::move(changed.labels);
  scenario->change_counts = changed.counts;
}

void PrepareOutput(const fs::path& out_dir, bool force) {
  std::error_code error;
  if (fs::exists(out_dir, error)) {
    CheckInput(fs::is_directory(out_dir, error), out_dir.string(), 0,
               "the output path exists and is not a folder", "choose a folder path for --out");
    const bool empty = fs::is_empty(out_dir, error);
    CheckInput(!error, out_dir.string(), 0, "cannot read the output folder: " + error.message(),
               "choose a readable, writable folder for --out");
    CheckInput(empty || force, out_dir.string(), 0, "the output folder is not empty",
               "choose an empty or new folder, or pass --force to overwrite the simulator's files");
    for (const fs::path& own :
         {out_dir / "sequences" / "00", out_dir / "poses" / "00.txt", out_dir / "world"}) {
      fs::remove_all(own, error);
    }
  }
  for (const char* sub : {"image_0", "image_1", "velodyne"}) {
    fs::create_directories(out_dir / "sequences" / "00" / sub, error);
    CheckInput(!error, out_dir.string(), 0, "cannot create the output folder: " + error.message(),
               "choose a writable location for --out");
  }
  fs::create_directories(out_dir / "poses", error);
  fs::create_directories(out_dir / "world", error);
  CheckInput(!error, out_dir.string(), 0, "cannot create the output folder: " + error.message(),
             "choose a writable location for --out");
}

std::string FrameName(int frame, const char* ext) {
  char name[32];
  std::snprintf(name, sizeof(name), "%06d.%s", frame, ext);
  return name;
}

void WriteReadme(const fs::path& path, const SimOptions& o, const Scenario& s) {
  std::ostringstream out;
  out << "planeloc sim: synthetic urban sequence (see docs/sim.md)\n"
      << "preset: " << o.preset << "\nseed: " << o.seed << "\nframes: " << s.world_from_cam.size()
      << "\nlighting: " << LightingName(o.lighting) << "\ntrajectory: "
      << (o.trajectory_path.empty() ? "(preset path)" : o.trajectory_path.string())
      << "\ntexture_dir: " << (o.texture_dir.empty() ? "(procedural)" : o.texture_dir.string())
      << "\npath_length_m: " << s.path_length << "\ngt_planes: " << s.LidarWorld().planes.size()
      << "\nprimitives: " << s.world.quads.size() << " quads, " << s.world.spheres.size()
      << " spheres, " << s.world.cylinders.size() << " cylinders\n";
  if (s.mapping_world) {
    const ChangeCounts& c = s.change_counts;
    out << "changes: " << o.changes.ToSpec() << " (" << c.moved_facades << " facades moved, "
        << c.removed_buildings << " buildings removed, " << c.new_walls << " walls new, "
        << c.parked_cars << " cars parked at mapping time only; the LiDAR scans the mapping-time "
        << "world, the cameras the world now)\n";
  }
  out << "poses/00.txt and world/planes_gt.json share one frame: camera 0 at frame 0 "
         "(x right, y down, z forward).\n";
  WriteFileWhole(path, out.str());
}

}  // namespace

Lighting ParseLighting(const std::string& name) {
  if (name == "constant") return Lighting::kConstant;
  if (name == "changing") return Lighting::kChanging;
  throw InputError("", "unknown lighting '" + name + "'", "use --lighting constant or changing");
}

std::string LightingName(Lighting lighting) {
  return lighting == Lighting::kConstant ? "constant" : "changing";
}

void SimOptions::Check() const {
  CheckInput(preset == "tiny" || preset == "small" || preset == "kitti07-like" ||
                 preset == "rural" || preset == "room",
             "", 0, "unknown preset '" + preset + "'", std::string("use one of: ") + kPresets);
  CheckInput(!frames || *frames > 0, "", 0, "--frames must be positive",
             "pass a frame count >= 1, or omit --frames for the preset's length");
  changes.Check();
  if (!texture_dir.empty()) {
    std::error_code error;
    CheckInput(fs::is_directory(texture_dir, error), texture_dir.string(), 0,
               "the texture folder does not exist or is not a folder",
               "pass a readable folder of png/jpg images to --texture-dir");
  }
  if (!trajectory_path.empty()) {
    std::ifstream probe(trajectory_path);
    CheckInput(static_cast<bool>(probe), trajectory_path.string(), 0,
               "cannot open the trajectory file",
               "pass a readable KITTI pose file to --trajectory");
  }
}

SimOptions SimOptions::FromPreset(const std::string& name) {
  SimOptions options;
  options.preset = name;
  options.Check();
  return options;
}

StereoCamera Kitti07Camera() {
  StereoCamera camera;
  camera.fx = camera.fy = 707.0912;
  camera.cx = 601.8873;
  camera.cy = 183.1104;
  camera.baseline = 0.537;
  camera.width = 1226;
  camera.height = 370;
  return camera;
}

Rigid3d Kitti07CamFromVelo() { return Rigid3d::FromMatrix3x4(Kitti07Tr()); }

Scenario BuildScenario(const SimOptions& options) {
  options.Check();
  if (options.preset == "room") return BuildRoomScenario(options);
  Scenario scenario;
  StreetPath street;
  if (!options.trajectory_path.empty()) {
    ScenarioFromPoseFile(options, options.frames.value_or(1 << 30), &scenario, &street);
  } else {
    ScenarioFromPreset(options, options.frames.value_or(PresetFrames(options.preset)), &scenario,
                       &street);
  }
  TownOptions town;
  town.rural = options.preset == "rural";
  scenario.world = BuildTown(street, HashCombine(options.seed, 1u), town);
  if (options.changes.Any()) ApplyChanges(options, street, &scenario);
  scenario.cam0_from_world = scenario.world_from_cam.front().Inverse();
  for (std::size_t i = 1; i < scenario.world_from_cam.size(); ++i) {
    scenario.path_length +=
        (scenario.world_from_cam[i].translation - scenario.world_from_cam[i - 1].translation)
            .norm();
  }
  return scenario;
}

SimResult GenerateSequence(const SimOptions& options, const fs::path& out_dir, bool force) {
  options.Check();
  if (options.preset == "room") return GenerateRoomSequence(options, out_dir, force);
  const TextureBank bank =
      options.texture_dir.empty()
          ? TextureBank::Procedural(HashCombine(options.seed, 3u))
          : TextureBank::WithWallImages(HashCombine(options.seed, 3u), options.texture_dir);
  const Scenario scenario = BuildScenario(options);
  PrepareOutput(out_dir, force);
  SimResult result;
  result.sequence_dir = out_dir / "sequences" / "00";
  result.poses_path = out_dir / "poses" / "00.txt";
  result.planes_path = out_dir / "world" / "planes_gt.json";
  result.frames = static_cast<int>(scenario.world_from_cam.size());
  result.camera = Kitti07Camera();
  result.cam_from_velo = Kitti07CamFromVelo();
  result.world_from_cam.push_back(Rigid3d::Identity());
  for (std::size_t i = 1; i < scenario.world_from_cam.size(); ++i) {
    result.world_from_cam.push_back(scenario.cam0_from_world * scenario.world_from_cam[i]);
  }
  WriteCalib(result.sequence_dir / "calib.txt", result.camera, Kitti07Tr());
  WriteTimes(result.sequence_dir / "times.txt", result.frames, kRateHz);
  WritePoses(result.poses_path, result.world_from_cam);
  if (scenario.mapping_world) {
    WritePlanesGtWithChanges(result.planes_path, *scenario.mapping_world, scenario.world,
                             scenario.plane_changes, scenario.change_counts,
                             options.changes.ToSpec(), scenario.cam0_from_world);
  } else {
    WritePlanesGt(result.planes_path, scenario.world, scenario.cam0_from_world);
  }
  WriteReadme(out_dir / "world" / "README.txt", options, scenario);

  const Scene scene(scenario.world);
  const Shader shader(scenario.world, bank);
  // With --changes the LiDAR scans the mapping-time world; otherwise the cameras' world.
  std::optional<Scene> mapping_scene;
  std::optional<Shader> mapping_shader;
  if (scenario.mapping_world) {
    mapping_scene.emplace(*scenario.mapping_world);
    mapping_shader.emplace(*scenario.mapping_world, bank);
  }
  const Scene& lidar_scene = mapping_scene ? *mapping_scene : scene;
  const Shader& lidar_shader = mapping_shader ? *mapping_shader : shader;
  const Rigid3d left_from_right(Eigen::Quaterniond::Identity(),
                                Eigen::Vector3d(result.camera.baseline, 0, 0));
  std::optional<ProgressBar> progress;  // none at all when disabled (not even a final line)
  if (options.show_progress)
    progress.emplace("sim", static_cast<std::size_t>(result.frames), "frames");
  // Frames in batches: threads render whole frames (and their rows) while the main thread alone
  // drives the progress bar. Every random stream is seeded per frame, so order does not matter.
  const int batch = std::max(2, 2 * tbb::this_task_arena::max_concurrency());
  for (int first = 0; first < result.frames; first += batch) {
    const int last = std::min(result.frames, first + batch);
    tbb::parallel_for(first, last, [&](int f) {
      const Rigid3d& world_from_cam = scenario.world_from_cam[static_cast<std::size_t>(f)];
      const FrameLighting light = LightingForFrame(options.lighting, options.seed, f);
      const auto seed = [&](std::uint32_t stream) {
        return HashCombine(options.seed, static_cast<std::uint32_t>(f), stream);
      };
      const cv::Mat left = RenderView(scene, shader, result.camera, world_from_cam, light, seed(0));
      const cv::Mat right = RenderView(scene, shader, result.camera,
                                       world_from_cam * left_from_right, light, seed(1));
      const VelodyneScan scan =
          ScanLidar(lidar_scene, lidar_shader, world_from_cam * result.cam_from_velo, seed(2));
      const std::string png = FrameName(f, "png");
      WritePng(result.sequence_dir / "image_0" / png, left);
      WritePng(result.sequence_dir / "image_1" / png, right);
      WriteScan(result.sequence_dir / "velodyne" / FrameName(f, "bin"), scan);
    });
    if (progress) progress->Update(static_cast<std::size_t>(last));
  }
  if (progress) progress->Finish();
  return result;
}

}  // namespace planeloc::sim
