// `planeloc sim`: a deterministic synthetic town rendered as a rectified KITTI-like stereo camera
// and scanned by an HDL-64E-like LiDAR, written in the KITTI odometry layout with exact ground
// truth (see docs/sim.md):
//
//   DIR/sequences/00/{image_0,image_1}/NNNNNN.png   1226x370 grey 8-bit, rectified
//   DIR/sequences/00/velodyne/NNNNNN.bin            float32 x, y, z, reflectance (velodyne frame)
//   DIR/sequences/00/{calib.txt,times.txt}          KITTI-07 intrinsics and Tr (cam_from_velo)
//   DIR/poses/00.txt                                world_from_cam of camera 0, first = identity
//   DIR/world/planes_gt.json                        GT planes in the poses' frame (ReadPlaneMap)
//   DIR/world/README.txt                            seed, preset, lighting (, changes)
//
// With SimOptions::changes (--changes) the LiDAR scans the world at mapping time and the cameras
// see it changed; planes_gt.json labels every plane (world_changes.h).
//
// Other modules' tests call GenerateSequence(SimOptions::FromPreset("tiny"), dir) to get data.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/sim/world.h"
#include "planeloc/sim/world_changes.h"

namespace planeloc::sim {

enum class Lighting {
  kConstant,  // fixed sun, exposure and gain
  kChanging,  // exposure/gain drift and a moving sun with cast shadows
};
// "constant" | "changing"; throws InputError otherwise.
Lighting ParseLighting(const std::string& name);
std::string LightingName(Lighting lighting);

struct SimOptions {
  std::string preset = "small";  // "tiny" (straight, ~60 frames) | "small" (one turn, ~300) |
                                 // "kitti07-like" (~700 m loop, >= 4 turns, 1101 frames) |
                                 // "room" (indoor flight, 600 frames, ASL layout: room_sequence.h)
  std::uint32_t seed = 1;        // determines the town, the motion jitter and all noise
  std::optional<int> frames;     // first N frames; unset = the preset's (or trajectory's) length
  Lighting lighting = Lighting::kConstant;
  std::filesystem::path texture_dir;      // images mapped onto facades; empty = procedural
  std::filesystem::path trajectory_path;  // KITTI pose file to drive along; empty = preset path
  WorldChangesOptions changes;            // --changes: the LiDAR's world vs the cameras'; none
  bool show_progress = true;              // progress bar on stderr (only when it is a terminal)

  // Throws InputError for an unknown preset, frames <= 0, an unreadable texture dir / pose file,
  // or changes out of range.
  void Check() const;
  // Defaults of a named preset; throws InputError for an unknown name.
  static SimOptions FromPreset(const std::string& name);
};

// What GenerateSequence wrote.
struct SimResult {
  std::filesystem::path sequence_dir;  // DIR/sequences/00 (open with KittiSequence::Open)
  std::filesystem::path poses_path;    // DIR/poses/00.txt
  std::filesystem::path planes_path;   // DIR/world/planes_gt.json
  int frames = 0;
  std::vector<Rigid3d> world_from_cam;  // camera-0 poses as written (first = identity)
  Rigid3d cam_from_velo;                // Tr as written to calib.txt
  StereoCamera camera;                  // intrinsics and baseline as written to calib.txt
};

// Renders the whole sequence into `out_dir` (created if missing). Refuses (InputError) a
// non-empty `out_dir` unless `force`, in which case the sim's own sub-folders are replaced.
// Uses all TBB threads; the bytes written do not depend on the thread count.
SimResult GenerateSequence(const SimOptions& options, const std::filesystem::path& out_dir,
                           bool force = false);

// The world and the camera motion of a run, before any rendering (tests and tools use it to
// compare sensor output with the truth). W is the simulator's z-up world frame (ground z = 0).
struct Scenario {
  World world;  // primitives and GT planes in W; with changes, the world the cameras see now
  // With changes only: the world at mapping time, which the LiDAR scans (unset: `world`).
  std::optional<World> mapping_world;
  // With changes only: one label per plane id of `world.planes` (empty without changes).
  std::vector<PlaneChangeLabel> plane_changes;
  ChangeCounts change_counts;           // with changes: what was changed
  std::vector<Rigid3d> world_from_cam;  // camera-0 poses in W, one per frame
  Rigid3d cam0_from_world;              // W -> the frame of poses/00.txt and planes_gt.json
  double path_length = 0.0;             // metres driven

  const World& LidarWorld() const { return mapping_world ? *mapping_world : world; }
};
// Throws InputError like SimOptions::Check (and for a malformed --trajectory file).
Scenario BuildScenario(const SimOptions& options);

// The KITTI-07 calibration the simulator writes.
StereoCamera Kitti07Camera();  // fx = fy = 707.0912, cx = 601.8873, cy = 183.1104, b = 0.537
Rigid3d Kitti07CamFromVelo();  // `Tr` of KITTI odometry sequence 07

}  // namespace planeloc::sim
