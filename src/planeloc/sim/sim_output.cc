#include "planeloc/sim/sim_output.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
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

// One GT plane in the output frame: {"id","kind","normal","d","centroid","area","polygon"}.
nlohmann::json PlaneJson(const GtPlane& gt, const Rigid3d& out_from_world) {
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
  return {{"id", gt.id},
          {"kind", gt.kind},
          {"normal", {plane.normal.x(), plane.normal.y(), plane.normal.z()}},
          {"d", plane.d},
          {"centroid", {centroid.x(), centroid.y(), centroid.z()}},
          {"area", area},
          {"polygon", polygon}};
}

// {"planes": planes, "stats": {...}} with the counts per kind of `gt_planes`.
nlohmann::json PlanesDocument(const nlohmann::json& planes, const std::vector<GtPlane>& gt_planes) {
  int counts[3] = {0, 0, 0};
  for (const GtPlane& gt : gt_planes)
    counts[gt.kind == "ground" ? 0 : gt.kind == "facade" ? 1 : 2]++;
  return {{"planes", planes},
          {"stats",
           {{"source", "planeloc sim"},
            {"frame", "camera 0 of frame 0 (the frame of poses/00.txt); n . x + d = 0"},
            {"ground", counts[0]},
            {"facade", counts[1]},
            {"other", counts[2]}}}};
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

void WritePng(const std::filesystem::path& path, const cv::Mat& image) {
  std::vector<unsigned char> png;
  CheckInput(cv::imencode(".png", image, png), path.string(), 0, "cannot encode the image",
             "report this as a bug");
  WriteFileWhole(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
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
  for (const GtPlane& gt : world.planes) planes.push_back(PlaneJson(gt, out_from_world));
  WriteFileWhole(path, PlanesDocument(planes, world.planes).dump(1) + "\n");
}

void WritePlanesGtWithChanges(const std::filesystem::path& path, const World& at_mapping,
                              const World& now, const std::vector<PlaneChangeLabel>& labels,
                              const ChangeCounts& counts, const std::string& spec,
                              const Rigid3d& out_from_world) {
  CheckInput(labels.size() == now.planes.size() && now.planes.size() >= at_mapping.planes.size(),
             path.string(), 0, "the change labels do not match the planes", "report this as a bug");
  int per_change[4] = {0, 0, 0, 0};
  nlohmann::json planes = nlohmann::json::array();
  nlohmann::json new_planes = nlohmann::json::array();
  for (std::size_t id = 0; id < now.planes.size(); ++id) {
    const PlaneChangeLabel& label = labels[id];
    ++per_change[static_cast<int>(label.change)];
    const bool mapped = id < at_mapping.planes.size();
    nlohmann::json plane =
        PlaneJson(mapped ? at_mapping.planes[id] : now.planes[id], out_from_world);
    plane["change"] = PlaneChangeName(label.change);
    if (label.change == PlaneChange::kMoved) plane["offset_m"] = label.offset_m;
    (mapped ? planes : new_planes).push_back(std::move(plane));
  }
  nlohmann::json document = PlanesDocument(planes, at_mapping.planes);
  document["new_planes"] = new_planes;
  document["stats"]["changes"] = {
      {"spec", spec},
      {"unchanged", per_change[static_cast<int>(PlaneChange::kUnchanged)]},
      {"moved", per_change[static_cast<int>(PlaneChange::kMoved)]},
      {"removed", per_change[static_cast<int>(PlaneChange::kRemoved)]},
      {"new", per_change[static_cast<int>(PlaneChange::kNew)]},
      {"removed_buildings", counts.removed_buildings},
      {"mapping_only_cars", counts.parked_cars},
      {"note",
       "planes: the mapping-time world (LiDAR); new_planes: walls built since (cameras); "
       "a moved plane is now n . x + (d - offset_m) = 0"}};
  WriteFileWhole(path, document.dump(1) + "\n");
}

}  // namespace planeloc::sim
