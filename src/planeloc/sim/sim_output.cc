#include "planeloc/sim/sim_output.h"

#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "planeloc/util/error.h"

namespace planeloc::sim {
namespace {

using FilePtr = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;

FilePtr OpenForWriting(const std::filesystem::path& path, const char* mode) {
  FilePtr file(std::fopen(path.c_str(), mode), &std::fclose);
  CheckInput(file != nullptr, path.string(), 0, "cannot open the file for writing",
             "check that the output folder is writable and the disk is not full");
  return file;
}

void WriteRow3x4(std::FILE* file, const Eigen::Matrix<double, 3, 4>& m) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c)
      std::fprintf(file, (r == 0 && c == 0) ? "%.12e" : " %.12e", m(r, c));
  }
}

}  // namespace

void WriteCalib(const std::filesystem::path& path, const StereoCamera& camera,
                const Eigen::Matrix<double, 3, 4>& cam_from_velo_3x4) {
  const auto file = OpenForWriting(path, "w");
  Eigen::Matrix<double, 3, 4> p0 = Eigen::Matrix<double, 3, 4>::Zero();
  p0.leftCols<3>() = camera.K();
  Eigen::Matrix<double, 3, 4> p1 = p0;
  p1(0, 3) = -camera.fx * camera.baseline;
  const std::pair<const char*, const Eigen::Matrix<double, 3, 4>*> rows[] = {
      {"P0", &p0}, {"P1", &p1}, {"P2", &p0}, {"P3", &p1}, {"Tr", &cam_from_velo_3x4}};
  for (const auto& [name, m] : rows) {
    std::fprintf(file.get(), "%s: ", name);
    WriteRow3x4(file.get(), *m);
    std::fprintf(file.get(), "\n");
  }
}

void WriteTimes(const std::filesystem::path& path, int frames, double rate_hz) {
  const auto file = OpenForWriting(path, "w");
  for (int i = 0; i < frames; ++i) std::fprintf(file.get(), "%.6e\n", i / rate_hz);
}

void WritePoses(const std::filesystem::path& path, const std::vector<Rigid3d>& world_from_cam) {
  const auto file = OpenForWriting(path, "w");
  for (const auto& pose : world_from_cam) {
    WriteRow3x4(file.get(), pose.Matrix3x4());
    std::fprintf(file.get(), "\n");
  }
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
  const auto file = OpenForWriting(path, "wb");
  const std::size_t written = std::fwrite(data.data(), sizeof(float), data.size(), file.get());
  CheckInput(written == data.size(), path.string(), 0, "short write", "check free disk space");
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
  std::ofstream out(path);
  CheckInput(static_cast<bool>(out), path.string(), 0, "cannot open the file for writing",
             "check that the output folder is writable");
  out << doc.dump(1) << "\n";
}

}  // namespace planeloc::sim
