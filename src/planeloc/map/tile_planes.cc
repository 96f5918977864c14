#include "planeloc/map/tile_planes.h"

#include <chrono>
#include <utility>

#include "planeloc/map/map_builder.h"
#include "planeloc/map/map_planes.h"

namespace planeloc {
namespace {

nlohmann::json ToJson(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }
Eigen::Vector3d Vector3FromJson(const nlohmann::json& j) {
  return {j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>()};
}

nlohmann::json PointsToJson(const std::vector<Eigen::Vector3d>& points) {
  std::vector<double> flat;
  flat.reserve(3 * points.size());
  for (const auto& p : points) flat.insert(flat.end(), {p.x(), p.y(), p.z()});
  return flat;
}
std::vector<Eigen::Vector3d> PointsFromJson(const nlohmann::json& j) {
  const auto flat = j.get<std::vector<double>>();
  std::vector<Eigen::Vector3d> points;
  points.reserve(flat.size() / 3);
  for (std::size_t i = 0; i + 2 < flat.size(); i += 3) {
    points.emplace_back(flat[i], flat[i + 1], flat[i + 2]);
  }
  return points;
}

nlohmann::json PlaneToJson(const MapPlane& p) {
  return {{"id", p.id},
          {"normal", ToJson(p.plane_in_map.normal)},
          {"d", p.plane_in_map.d},
          {"kind", p.kind},
          {"centroid", ToJson(p.centroid)},
          {"inliers", p.inliers},
          {"rms", p.rms},
          {"area", p.area},
          {"polygon", PointsToJson(p.polygon)}};
}
MapPlane PlaneFromJson(const nlohmann::json& j) {
  MapPlane p;
  p.id = j.at("id").get<int>();
  p.plane_in_map.normal = Vector3FromJson(j.at("normal"));  // already unit: no renormalization
  p.plane_in_map.d = j.at("d").get<double>();
  p.kind = j.at("kind").get<std::string>();
  p.centroid = Vector3FromJson(j.at("centroid"));
  p.inliers = j.at("inliers").get<int>();
  p.rms = j.at("rms").get<double>();
  p.area = j.at("area").get<double>();
  p.polygon = PointsFromJson(j.at("polygon"));
  return p;
}

// One piece from the inliers of a tile plane (indices into `points`).
TilePiece MakePiece(const MapPlane& plane, const std::vector<Eigen::Vector3d>& points,
                    const std::vector<int>& inliers, const TileKey& key, const TileGrid& grid,
                    double cell_size) {
  TilePiece piece;
  piece.plane = plane;
  std::vector<Eigen::Vector3d> core, band;
  for (const int i : inliers) {
    (grid.InCore(key, points[i]) ? core : band).push_back(points[i]);
  }
  piece.band_samples = VoxelDownsample(band, cell_size);
  piece.complete = core.size() == inliers.size();
  piece.core_inliers = core.size();
  if (core.empty()) return piece;
  for (const auto& p : core) piece.core_mean += p;
  piece.core_mean /= static_cast<double>(core.size());
  for (const auto& p : core) {
    const Eigen::Vector3d r = p - piece.core_mean;
    piece.core_scatter.noalias() += r * r.transpose();
  }
  piece.samples = VoxelDownsample(core, cell_size);
  return piece;
}

}  // namespace

nlohmann::json TilePlanes::ToJson() const {
  nlohmann::json json = {{"key", {key[0], key[1]}}, {"file", file}, {"error", error}};
  if (!error.empty()) return json;
  nlohmann::json pieces_json = nlohmann::json::array();
  for (const TilePiece& p : pieces) {
    const Eigen::Matrix3d& s = p.core_scatter;
    pieces_json.push_back({{"plane", PlaneToJson(p.plane)},
                           {"complete", p.complete},
                           {"core_inliers", p.core_inliers},
                           {"core_mean", planeloc::ToJson(p.core_mean)},
                           {"core_scatter", {s(0, 0), s(0, 1), s(0, 2), s(1, 1), s(1, 2), s(2, 2)}},
                           {"samples", PointsToJson(p.samples)},
                           {"band_samples", PointsToJson(p.band_samples)}});
  }
  json.update({{"points", points},
               {"core_points", core_points},
               {"up", planeloc::ToJson(up)},
               {"up_detected", up_detected},
               {"seconds", seconds},
               {"pieces", pieces_json}});
  if (gt) json["gt"] = gt->ToJson();
  return json;
}

TilePlanes TilePlanes::FromJson(const nlohmann::json& json) {
  TilePlanes tile;
  tile.key = {json.at("key").at(0).get<long long>(), json.at("key").at(1).get<long long>()};
  tile.file = json.at("file").get<std::string>();
  tile.error = json.at("error").get<std::string>();
  if (!tile.error.empty()) return tile;
  tile.points = json.at("points").get<std::size_t>();
  tile.core_points = json.at("core_points").get<std::size_t>();
  tile.up = Vector3FromJson(json.at("up"));
  tile.up_detected = json.at("up_detected").get<bool>();
  tile.seconds = json.at("seconds").get<double>();
  for (const auto& j : json.at("pieces")) {
    TilePiece p;
    p.plane = PlaneFromJson(j.at("plane"));
    p.complete = j.at("complete").get<bool>();
    p.core_inliers = j.at("core_inliers").get<std::size_t>();
    p.core_mean = Vector3FromJson(j.at("core_mean"));
    const auto s = j.at("core_scatter").get<std::vector<double>>();
    p.core_scatter << s.at(0), s.at(1), s.at(2), s.at(1), s.at(3), s.at(4), s.at(2), s.at(4),
        s.at(5);
    p.samples = PointsFromJson(j.at("samples"));
    p.band_samples = PointsFromJson(j.at("band_samples"));
    tile.pieces.push_back(std::move(p));
  }
  if (json.contains("gt")) tile.gt = PlaneMapTally::FromJson(json.at("gt"));
  return tile;
}

TilePlanes ExtractTilePlanes(const PointCloud& tile, const TileKey& key, const TileGrid& grid,
                             const MapPlanesOptions& options, const PlaneMap* gt,
                             const PlaneMapEvalOptions& eval_options) {
  const auto start = std::chrono::steady_clock::now();
  const MapPlanesOutput output = RunMapPlanes(tile, options);
  TilePlanes result;
  result.key = key;
  result.points = output.points.size();
  result.up = output.extraction.up;
  result.up_detected = output.extraction.up_detected;
  const std::vector<int>& labels = output.extraction.point_plane;
  const auto& planes = output.extraction.plane_map.planes;
  std::vector<std::vector<int>> inliers(planes.size());
  std::vector<Eigen::Vector3d> core_points;
  std::vector<int> core_labels;
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] >= 0) inliers[labels[i]].push_back(static_cast<int>(i));
    if (grid.InCore(key, output.points[i])) {
      core_points.push_back(output.points[i]);
      core_labels.push_back(labels[i]);
    }
  }
  result.core_points = core_points.size();
  for (std::size_t id = 0; id < planes.size(); ++id) {
    TilePiece piece = MakePiece(planes[id], output.points, inliers[id], key, grid,
                                options.plane_extraction.outline.cell_size);
    if (piece.core_inliers > 0) result.pieces.push_back(std::move(piece));
  }
  if (gt != nullptr) result.gt = TallyPlaneMap(core_points, core_labels, *gt, eval_options);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace planeloc
