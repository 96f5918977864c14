// KITTI raw OXTS packets (GPS/IMU) and their conversion to poses, following the KITTI raw devkit
// (convertOxtsToPose.m, latToScale.m, latlonToMercator.m). See docs/io.md for the derivation.
//
// IMU frame (OXTS unit): x forward, y left, z up. The devkit's "world" is a local Mercator frame:
// x east, y north, z up (altitude), scaled by cos(lat0) so that metres are true near the start.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <vector>

#include "planeloc/geometry/rigid3.h"

namespace planeloc {

// The fields of one OXTS packet that define its pose (the file holds 30 values; see
// oxts/dataformat.txt).
struct OxtsPacket {
  double lat_deg = 0;  // latitude, degrees
  double lon_deg = 0;  // longitude, degrees
  double alt_m = 0;    // altitude, metres
  double roll = 0;     // radians, 0 = level, positive = left side up
  double pitch = 0;    // radians, positive = front down
  double yaw = 0;      // radians, 0 = east, positive = counter-clockwise
};

// Reads one `oxts/data/NNNNNNNNNN.txt`. Throws InputError (file, line 1) when it is missing, has
// fewer than 30 values or a non-finite one.
OxtsPacket ReadOxtsPacket(const std::filesystem::path& path);

// Earth radius (m) used by the devkit's Mercator projection.
inline constexpr double kOxtsEarthRadius = 6378137.0;

// Mercator scale of the first packet's latitude: cos(lat0 * pi / 180).
double MercatorScale(double lat0_deg);
// (mx, my) in metres: mx = s * pi * er * lon / 180, my = s * er * ln(tan((90 + lat) * pi / 360)).
Eigen::Vector2d LatLonToMercator(double lat_deg, double lon_deg, double scale);

// world_from_imu of each packet in the Mercator frame (translation (mx, my, alt), rotation
// Rz(yaw) Ry(pitch) Rx(roll)), scale from the first packet.
std::vector<Rigid3d> OxtsToWorldFromImu(const std::vector<OxtsPacket>& packets);
// The devkit's convertOxtsToPose: imu0_from_imu_i = world_from_imu_0^-1 * world_from_imu_i, so the
// first pose is the identity.
std::vector<Rigid3d> OxtsToImuPoses(const std::vector<OxtsPacket>& packets);

// Camera poses from IMU poses: world_from_cam_i = cam_from_imu * imu0_from_imu_i * imu_from_cam,
// i.e. the IMU trajectory expressed as the trajectory of a rigidly attached camera, in the first
// camera's frame (first pose identity when the first IMU pose is).
std::vector<Rigid3d> ImuPosesToCameraPoses(const std::vector<Rigid3d>& imu0_from_imu,
                                           const Rigid3d& cam_from_imu);

}  // namespace planeloc
