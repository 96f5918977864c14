#include "planeloc/sim/room_sequence.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <optional>
#include <sstream>

#include "planeloc/io/asl_sequence.h"
#include "planeloc/io/point_cloud.h"
#include "planeloc/sim/asl_output.h"
#include "planeloc/sim/render.h"
#include "planeloc/sim/room.h"
#include "planeloc/sim/shading.h"
#include "planeloc/sim/sim_output.h"
#include "planeloc/sim/survey_scan.h"
#include "planeloc/sim/texture.h"
#include "planeloc/util/error.h"
#include "planeloc/util/progress.h"
#include "planeloc/util/safe_file.h"

namespace planeloc::sim {
namespace {

namespace fs = std::filesystem;

// EuRoC's cameras expose for a few milliseconds indoors; at the preset's fastest turns (80 deg/s)
// 5 ms smear the image by about 3 pixels, which is the blur the issue asks for.
constexpr double kExposureSeconds = 0.005;
// The survey is thinned to one point per 1 cm cube, about a Leica scan's density on the walls.
constexpr double kSurveyVoxel = 0.01;

// Indoor light: ceiling lamps (mostly from above) and much diffuse light, no cast shadows.
FrameLighting RoomLighting() {
  FrameLighting light;
  light.to_sun = Eigen::Vector3f(0.3f, 0.2f, 0.93f).normalized();
  light.sun = 0.3f;
  light.ambient = 0.62f;
  return light;
}

StereoCamera CameraOf(const AslCamera& asl) {
  StereoCamera camera;
  camera.fx = asl.fu;
  camera.fy = asl.fv;
  camera.cx = asl.cu;
  camera.cy = asl.cv;
  camera.width = asl.width;
  camera.height = asl.height;
  return camera;
}

double FrameTime(int frame) { return frame / kRoomRateHz; }

void PrepareRoomOutput(const fs::path& out_dir, bool force) {
  std::error_code error;
  if (fs::exists(out_dir, error)) {
    CheckInput(fs::is_directory(out_dir, error), out_dir.string(), 0,
               "the output path exists and is not a folder", "choose a folder path for --out");
    const bool empty = fs::is_empty(out_dir, error);
    CheckInput(empty || force, out_dir.string(), 0, "the output folder is not empty",
               "choose an empty or new folder, or pass --force to overwrite the simulator's files");
    for (const fs::path& own : {out_dir / "mav0", out_dir / "poses", out_dir / "world"}) {
      fs::remove_all(own, error);
    }
  }
  for (const fs::path& sub :
       {out_dir / "mav0" / "cam0" / "data", out_dir / "mav0" / "cam1" / "data",
        out_dir / "mav0" / "state_groundtruth_estimate0", out_dir / "mav0" / "pointcloud0",
        out_dir / "poses", out_dir / "world"}) {
    fs::create_directories(sub, error);
    CheckInput(!error, out_dir.string(), 0, "cannot create the output folder: " + error.message(),
               "choose a writable location for --out");
  }
}

void WriteRoomReadme(const fs::path& path, const SimOptions& o, const Scenario& s,
                     std::size_t survey_points) {
  std::ostringstream out;
  out << "planeloc sim: synthetic indoor sequence, ASL / EuRoC MAV layout (see docs/sim.md)\n"
      << "preset: room\nseed: " << o.seed << "\nframes: " << s.world_from_cam.size()
      << "\nrate_hz: " << kRoomRateHz << "\nexposure_s: " << kExposureSeconds
      << "\npath_length_m: " << s.path_length << "\ngt_planes: " << s.world.planes.size()
      << "\nsurvey_points: " << survey_points
      << " (3 stations, 1 cm voxels)\nprimitives: " << s.world.quads.size() << " quads, "
      << s.world.spheres.size() << " spheres, " << s.world.cylinders.size() << " cylinders\n"
      << "cameras: EuRoC's cam0/cam1 calibration (radial-tangential), raw images\n"
      << "frame: everything in the room's frame W (z up, floor at z = 0): the ground truth, "
         "poses/00.txt (the rectified left camera), planes_gt.json and pointcloud0/data.ply.\n";
  WriteFileWhole(path, out.str());
}

}  // namespace

Scenario BuildRoomScenario(const SimOptions& options) {
  CheckInput(options.trajectory_path.empty(), options.trajectory_path.string(), 0,
             "--trajectory drives the street presets; the room preset flies its own path",
             "leave out --trajectory with --preset room");
  CheckInput(!options.changes.Any(), "", 0, "--changes is not available for the room preset",
             "leave out --changes with --preset room");
  const RoomOptions room;
  Scenario scenario;
  scenario.world = BuildRoom(HashCombine(options.seed, 1u), room);
  const RoomFlight flight(room, FlightOptions{}, HashCombine(options.seed, 2u));
  const int frames = options.frames.value_or(kRoomFrames);
  for (int f = 0; f < frames; ++f)
    scenario.world_from_cam.push_back(flight.WorldFromCamAt(FrameTime(f)));
  scenario.cam0_from_world = Rigid3d::Identity();  // the outputs stay in W
  for (std::size_t i = 1; i < scenario.world_from_cam.size(); ++i) {
    scenario.path_length +=
        (scenario.world_from_cam[i].translation - scenario.world_from_cam[i - 1].translation)
            .norm();
  }
  return scenario;
}

SimResult GenerateRoomSequence(const SimOptions& options, const fs::path& out_dir, bool force) {
  options.Check();
  const Scenario scenario = BuildRoomScenario(options);
  const TextureBank bank =
      options.texture_dir.empty()
          ? TextureBank::Procedural(HashCombine(options.seed, 3u))
          : TextureBank::WithWallImages(HashCombine(options.seed, 3u), options.texture_dir);
  PrepareRoomOutput(out_dir, force);
  const fs::path mav0 = out_dir / "mav0";
  const AslCamera cam0 = EurocCam0(), cam1 = EurocCam1();
  const int frames = static_cast<int>(scenario.world_from_cam.size());
  std::vector<std::int64_t> stamps;
  for (int f = 0; f < frames; ++f) {
    stamps.push_back(kRoomFirstStampNs + static_cast<std::int64_t>(f) * 50'000'000);
  }
  const RoomFlight flight(RoomOptions{}, FlightOptions{}, HashCombine(options.seed, 2u));
  const Rigid3d cam0_from_body = cam0.body_from_sensor.Inverse();
  const auto body_at = [&](double t) { return flight.WorldFromCamAt(t) * cam0_from_body; };
  std::vector<Rigid3d> world_from_body;
  for (int f = 0; f < frames; ++f) world_from_body.push_back(body_at(FrameTime(f)));

  WriteAslCameraYaml(mav0 / "cam0" / "sensor.yaml", cam0, "VI-Sensor cam0 (planeloc sim, room)");
  WriteAslCameraYaml(mav0 / "cam1" / "sensor.yaml", cam1, "VI-Sensor cam1 (planeloc sim, room)");
  WriteAslImageList(mav0 / "cam0" / "data.csv", stamps);
  WriteAslImageList(mav0 / "cam1" / "data.csv", stamps);
  const fs::path gt_csv = mav0 / "state_groundtruth_estimate0" / "data.csv";
  WriteAslGroundTruth(gt_csv, stamps, world_from_body);
  WritePlanesGt(out_dir / "world" / "planes_gt.json", scenario.world, Rigid3d::Identity());

  const Scene scene(scenario.world);
  const Shader shader(scenario.world, bank);
  // The prior map: a survey from three tripod stations, merged and thinned.
  PointCloud survey;
  survey.points = ScanSurveyStations(scene, RoomSurveyStations(RoomOptions{}),
                                     HashCombine(options.seed, 4u), kSurveyVoxel);
  survey.comments.push_back("planeloc sim room survey: 3 stations, 1 cm voxels, frame W");
  WritePointCloud(mav0 / "pointcloud0" / "data.ply", survey);
  WriteRoomReadme(out_dir / "world" / "README.txt", options, scenario, survey.size());

  CameraRenderOptions render0, render1;
  render0.distortion = cam0.distortion;
  render1.distortion = cam1.distortion;
  const StereoCamera camera0 = CameraOf(cam0), camera1 = CameraOf(cam1);
  const FrameLighting light = RoomLighting();
  std::optional<ProgressBar> progress;
  if (options.show_progress) progress.emplace("sim", static_cast<std::size_t>(frames), "frames");
  const int batch = std::max(2, 2 * tbb::this_task_arena::max_concurrency());
  for (int first = 0; first < frames; first += batch) {
    const int last = std::min(frames, first + batch);
    tbb::parallel_for(first, last, [&](int f) {
      const double t = FrameTime(f);
      const Rigid3d open = body_at(t - 0.5 * kExposureSeconds);
      const Rigid3d close = body_at(t + 0.5 * kExposureSeconds);
      const auto seed = [&](std::uint32_t stream) {
        return HashCombine(options.seed, static_cast<std::uint32_t>(f), stream);
      };
      const cv::Mat left =
          RenderViewDuringExposure(scene, shader, camera0, open * cam0.body_from_sensor,
                                   close * cam0.body_from_sensor, light, seed(0), render0);
      const cv::Mat right =
          RenderViewDuringExposure(scene, shader, camera1, open * cam1.body_from_sensor,
                                   close * cam1.body_from_sensor, light, seed(1), render1);
      const std::string name = AslImageName(stamps[static_cast<std::size_t>(f)]);
      WritePng(mav0 / "cam0" / "data" / name, left);
      WritePng(mav0 / "cam1" / "data" / name, right);
    });
    if (progress) progress->Update(static_cast<std::size_t>(last));
  }
  if (progress) progress->Finish();

  // The rectified left camera as the reader rectifies it: the poses every other preset writes.
  const AslSequence sequence = AslSequence::Open(mav0);
  SimResult result;
  result.sequence_dir = mav0;
  result.poses_path = out_dir / "poses" / "00.txt";
  result.planes_path = out_dir / "world" / "planes_gt.json";
  result.frames = frames;
  result.camera = sequence.camera();
  for (const Rigid3d& body : world_from_body) {
    result.world_from_cam.push_back(body * sequence.body_from_camera());
  }
  WritePoses(result.poses_path, result.world_from_cam);
  return result;
}

}  // namespace planeloc::sim
