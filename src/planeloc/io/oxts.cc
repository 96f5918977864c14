#include "planeloc/io/oxts.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <string>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr int kOxtsValues = 30;

}  // namespace

OxtsPacket ReadOxtsPacket(const std::filesystem::path& path) {
  std::ifstream stream(path);
  CheckInput(stream.good(), path.string(), 0, "OXTS packet file missing or unreadable",
             "every frame of a KITTI raw drive needs oxts/data/<frame>.txt; delete the oxts folder "
             "to load the drive without ground truth");
  std::vector<double> values;
  std::string token;
  while (stream >> token) {
    double value = 0;
    try {
      std::size_t used = 0;
      value = std::stod(token, &used);
      if (used != token.size()) throw std::invalid_argument(token);
    } catch (const std::exception&) {
      throw InputError(path.string(), 1, fmt::format("OXTS value '{}' is not a number", token),
                       "restore the packet from the original KITTI raw drive");
    }
    CheckInput(std::isfinite(value) || values.size() >= 6, path.string(), 1,
               fmt::format("OXTS value {} is not finite", values.size() + 1),
               "restore the packet from the original KITTI raw drive");
    values.push_back(value);
  }
  CheckInput(values.size() >= kOxtsValues, path.string(), 1,
             fmt::format("OXTS packet has {} values, expected {}", values.size(), kOxtsValues),
             "restore the packet from the original KITTI raw drive (see oxts/dataformat.txt)");
  return OxtsPacket{values[0], values[1], values[2], values[3], values[4], values[5]};
}

double MercatorScale(double lat0_deg) { return std::cos(lat0_deg * M_PI / 180.0); }

Eigen::Vector2d LatLonToMercator(double lat_deg, double lon_deg, double scale) {
  const double mx = scale * lon_deg * M_PI * kOxtsEarthRadius / 180.0;
  const double my = scale * kOxtsEarthRadius * std::log(std::tan((90.0 + lat_deg) * M_PI / 360.0));
  return Eigen::Vector2d(mx, my);
}

std::vector<Rigid3d> OxtsToWorldFromImu(const std::vector<OxtsPacket>& packets) {
  std::vector<Rigid3d> world_from_imu;
  if (packets.empty()) return world_from_imu;
  const double scale = MercatorScale(packets.front().lat_deg);
  world_from_imu.reserve(packets.size());
  for (const OxtsPacket& packet : packets) {
    const Eigen::Vector2d mercator = LatLonToMercator(packet.lat_deg, packet.lon_deg, scale);
    const Eigen::Matrix3d rotation = (Eigen::AngleAxisd(packet.yaw, Eigen::Vector3d::UnitZ()) *
                                      Eigen::AngleAxisd(packet.pitch, Eigen::Vector3d::UnitY()) *
                                      Eigen::AngleAxisd(packet.roll, Eigen::Vector3d::UnitX()))
                                         .toRotationMatrix();
    world_from_imu.emplace_back(rotation,
                                Eigen::Vector3d(mercator.x(), mercator.y(), packet.alt_m));
  }
  return world_from_imu;
}

std::vector<Rigid3d> OxtsToImuPoses(const std::vector<OxtsPacket>& packets) {
  std::vector<Rigid3d> world_from_imu = OxtsToWorldFromImu(packets);
  if (world_from_imu.empty()) return world_from_imu;
  // Mercator coordinates are ~1e6 m; Rigid3d composes in double, leaving ~1e-10 m of rounding.
  const Rigid3d imu0_from_world = world_from_imu.front().Inverse();
  for (Rigid3d& pose : world_from_imu) pose = imu0_from_world * pose;
  return world_from_imu;
}

std::vector<Rigid3d> ImuPosesToCameraPoses(const std::vector<Rigid3d>& imu0_from_imu,
                                           const Rigid3d& cam_from_imu) {
  const Rigid3d imu_from_cam = cam_from_imu.Inverse();
  std::vector<Rigid3d> world_from_cam;
  world_from_cam.reserve(imu0_from_imu.size());
  for (const Rigid3d& pose : imu0_from_imu)
    world_from_cam.push_back(cam_from_imu * pose * imu_from_cam);
  return world_from_cam;
}

}  // namespace planeloc
