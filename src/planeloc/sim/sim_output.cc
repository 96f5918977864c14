#include "planeloc/sim/sim_output.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <string>

#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

namespace planeloc::sim {
namespace {

std::string Row3x4(const Eigen::Matrix<double, 3, 4>& m) {
  std::string row;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      if (r != 0 || c != 0) row += ' ';
      row += fmt::format("{:.12e}", m(r, c));
    }
  }
  return row;
}

}  // namespace

void WriteCalib(const std::filesystem::path& path, const StereoCamera& camera,
                const Eigen::Matrix<double, 3, 4>& cam_from_velo_3x4) {
  std::string text;
  Eigen::Matrix<double, 3, 4> p0 = Eigen::Matrix<double, 3, 4>::Zero();
  p0.leftCols<3>() = camera.K();
  Eigen::Matrix<double, 3, 4> p1 = p0;
  p1(0, 3) = -camera.fx * camera.baseline;
  const std::pair<const char*, const Eigen::Matrix<double, 3, 4>*> rows[] = {
      {"P0", &p0}, {"P1", &p1}, {"P2", &p0}, {"P3", &p1}, {"Tr", &cam_from_velo_3x4}};
  for (const auto& [name, m] : rows) text += fmt::format("{}: {}\n", name, Row3x4(*m));
  WriteFileWhole(path, text);
}

void WriteTimes(const std::filesystem::path& path, int frames, double rate_hz) {
  std::string text;
  for (int i = 0; i < frames; ++i) text += fmt::format("{:.6e}\n", i / rate_hz);
  WriteFileWhole(path, text);
}

void WritePoses(const std::filesystem::path& path, const std::vector<Rigid3d>& world_from_cam) {
  std::string text;
  for (const auto& pose : world_from_cam) text += Row3x4(pose.Matrix3x4()) + '\n';
  WriteFileWhole(path, text);
}

void WriteScan(const std::filesystem::path& path, const VelodyneScan& scan) {
  std::vector<float> data;
  data.reserve(scan.points.size() * 4);
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    data.push_back(static_cast<float>(scan.points[i].x()));
    data.push_back(static_cast<float>(scan.points[i].y()));
    data.push_back(static_cast<float>(scan.points[i].z()));
    data.push_back(i < scan.reflectance.size() ? scan.reflectance[i] : 0.0f);
  }
  WriteFileWhole(path, std::string_view(reinterpret_cast<const char*>(data.data()),
                                        data.size() * sizeof(float)));
}

void WritePlanesGt(const std::filesystem::path& path, const World& world,
                   const Rigid3d& out_from_world) {
  nlohmann::json planes = nlohmann::json::array();
  int counts[3] = {0, 0, 0};
  for (const GtPlane& gt : world.planes) {
    const Plane plane = gt.plane.Transformed(out_from_world);
    nlohmann::json polygon = nlohmann::json::array();
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    for (const auto& corner : gt.polygon) {
      const Eigen::Vector3d p = out_from_world * corner;
      polygon.push_back({p.x(), p.y(), p.z()});
      centroid += p / static_cast<double>(gt.polygon.size());
    }
    double area = 0.0;  // polygon area (fan triangulation, convex polygons)
    for (std::size_t i = 1; i + 1 < gt.polygon.size(); ++i) {
      area += 0.5 * (gt.polygon[i] - gt.polygon[0]).cross(gt.polygon[i + 1] - gt.polygon[0]).norm();
    }
    counts[gt.kind == "ground" ? 0 : gt.kind == "facade" ? 1 : 2]++;
    planes.push_back({{"id", gt.id},
                      {"kind", gt.kind},
                      {"normal", {plane.normal.x(), plane.normal.y(), plane.normal.z()}},
                      {"d", plane.d},
                      {"centroid", {centroid.x(), centroid.y(), centroid.z()}},
                      {"area", area},
                      {"polygon", polygon}});
  }
  const nlohmann::json doc = {
      {"planes", planes},
      {"stats",
       {{"source", "planeloc sim"},
        {"frame", "camera 0 of frame 0 (the frame of poses/00.txt); n . x + d = 0"},
        {"ground", counts[0]},
        {"facade", counts[1]},
        {"other", counts[2]}}}};
  WriteFileWhole(path, doc.dump(1) + "\n");
}

}  // namespace planeloc::sim
