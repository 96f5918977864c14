// Writers of the simulator's KITTI-layout files (calib.txt, times.txt, poses, velodyne .bin,
// planes_gt.json). Formats follow the KITTI odometry devkit; numbers use %.12e like KITTI's.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/rigid3.h"
#include "planeloc/io/kitti_sequence.h"
#include "planeloc/sim/world.h"
#include "planeloc/sim/world_changes.h"

namespace planeloc::sim {

// P0 = K [I | 0], P1 = K [I | -b e_x] (P1(0,3) = -fx b), P2 = P0, P3 = P1 (no colour pair is
// rendered), Tr = the 3x4 of `cam_from_velo_3x4` (written verbatim).
void WriteCalib(const std::filesystem::path& path, const StereoCamera& camera,
                const Eigen::Matrix<double, 3, 4>& cam_from_velo_3x4);
void WriteTimes(const std::filesystem::path& path, int frames, double rate_hz);
void WritePoses(const std::filesystem::path& path, const std::vector<Rigid3d>& world_from_cam);
// PNG-encoded in memory and written whole: complete or absent, a failed write an InputError.
void WritePng(const std::filesystem::path& path, const cv::Mat& image);
// float32 little-endian x, y, z, reflectance per point.
void WriteScan(const std::filesystem::path& path, const VelodyneScan& scan);
// GT planes of `world` expressed in the output frame: {"planes":[{"id","kind","normal","d",
// "polygon","centroid","area"}], "stats":{...}}, readable by planeloc::ReadPlaneMap.
void WritePlanesGt(const std::filesystem::path& path, const World& world,
                   const Rigid3d& out_from_world);
// The same file for a changed world (--changes): "planes" holds the mapping-time planes (what the
// LiDAR saw: the planes of a map), each with "change": "unchanged" | "moved" (+ "offset_m") |
// "removed"; "new_planes" holds the walls built since ("change": "new"), which existing readers
// (ReadPlaneMap) do not load, so the file stays a prior map of the world at mapping time.
// "stats"."changes" gives the spec and the counts. `labels` is indexed by plane id of `now`.
void WritePlanesGtWithChanges(const std::filesystem::path& path, const World& at_mapping,
                              const World& now, const std::vector<PlaneChangeLabel>& labels,
                              const ChangeCounts& counts, const std::string& spec,
                              const Rigid3d& out_from_world);

}  // namespace planeloc::sim
