// `planeloc sim --preset room` (issue 35): the indoor preset written in the ASL / EuRoC MAV layout,
// as a Vicon-room sequence with a surveyed point cloud is delivered:
//
//   DIR/mav0/cam0/{sensor.yaml,data.csv,data/<ns>.png}   raw 752x480 grey, EuRoC's cam0 (radtan)
//   DIR/mav0/cam1/...                                    EuRoC's cam1
//   DIR/mav0/state_groundtruth_estimate0/data.csv        body (IMU) poses at every frame, ns
//   DIR/mav0/pointcloud0/data.ply                        the survey scan: the prior map, in W
//   DIR/poses/00.txt          the rectified left camera in W, one KITTI line per frame (eval)
//   DIR/world/planes_gt.json  GT planes in W;  DIR/world/README.txt  what was generated
//
// Everything is in the room's frame W (z up, floor z = 0): unlike the street presets, no pose is
// the identity, as in EuRoC, whose ground truth and scan share the Vicon frame.
#pragma once

#include <filesystem>

#include "planeloc/sim/simulator.h"

namespace planeloc::sim {

// 20 Hz, EuRoC's timestamps of V1_01's first frame onwards.
inline constexpr double kRoomRateHz = 20.0;
inline constexpr std::int64_t kRoomFirstStampNs = 1403715273262142976;
inline constexpr int kRoomFrames = 600;  // 30 s, about 21 m of flight

// The room, the camera-0 (raw, unrectified) poses of every frame and the frame of the outputs.
Scenario BuildRoomScenario(const SimOptions& options);

// Writes the room preset into `out_dir` (see above); `force` as GenerateSequence.
SimResult GenerateRoomSequence(const SimOptions& options, const std::filesystem::path& out_dir,
                               bool force);

}  // namespace planeloc::sim
