#include "planeloc/io/plane_map.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>

#include "planeloc/io/json_text.h"
#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

namespace planeloc {
namespace {

using nlohmann::json;

// |n| may deviate from 1 by this much (rounding of a written file) before it is an error.
constexpr double kNormalTolerance = 1e-3;

const char* kSchemaFix =
    "planes.json holds {\"planes\":[{\"id\":int,\"normal\":[nx,ny,nz],\"d\":number,...}]}; "
    "regenerate it with `planeloc map`";

// Validates one plane's fields; `where` names the plane for messages ("plane 3").
class PlaneReader {
 public:
  PlaneReader(const std::string& path, const json& object, std::string where)
      : path_(path), object_(object), where_(std::move(where)) {}

  void Fail(const std::string& what) const {
    throw InputError(path_, fmt::format("{}: {}", where_, what), kSchemaFix);
  }
  // Fail with a line (0: unknown).
  void FailAt(int line, const std::string& what, const std::string& fix) const {
    throw InputError(path_, line, fmt::format("{}: {}", where_, what), fix);
  }

  double Number(const json& value, const std::string& field) const {
    if (!value.is_number()) Fail(fmt::format("`{}` is not a number", field));
    const double number = value.get<double>();
    if (!std::isfinite(number)) Fail(fmt::format("`{}` is not finite", field));
    return number;
  }

  Eigen::Vector3d Vector(const json& value, const std::string& field) const {
    if (!value.is_array() || value.size() != 3) {
      Fail(fmt::format("`{}` must be an array of 3 numbers", field));
    }
    return Eigen::Vector3d(Number(value[0], field), Number(value[1], field),
                           Number(value[2], field));
  }

  bool Has(const std::string& field) const {
    return object_.contains(field) && !object_[field].is_null();
  }
  const json& operator[](const std::string& field) const { return object_[field]; }

  // A required unit normal and offset; a normal within kNormalTolerance of unit length is
  // normalized together with d (same plane), anything else is an error.
  Plane ReadPlane() const {
    if (!Has("normal") || !Has("d")) Fail("`normal` and `d` are required");
    const Eigen::Vector3d normal = Vector(object_["normal"], "normal");
    const double d = Number(object_["d"], "d");
    const double norm = normal.norm();
    if (std::abs(norm - 1.0) > kNormalTolerance) {
      Fail(fmt::format("|normal| = {:.6g}, expected 1 (tolerance {})", norm, kNormalTolerance));
    }
    if (std::abs(norm - 1.0) <= 4 * std::numeric_limits<double>::epsilon()) {
      // Already unit: keep the bits, so that a written map reads back exactly.
      Plane plane;
      plane.normal = normal;
      plane.d = d;
      return plane;
    }
    return Plane(normal, d);
  }

  int Integer(const std::string& field, int fallback) const {
    if (!Has(field)) return fallback;
    if (!object_[field].is_number_integer()) Fail(fmt::format("`{}` is not an integer", field));
    return object_[field].get<int>();
  }

  double OptionalNumber(const std::string& field) const {
    return Has(field) ? Number(object_[field], field) : 0.0;
  }

 private:
  const std::string& path_;
  const json& object_;
  std::string where_;
};

// Line (1-based) of the `occurrence`-th (0-based) appearance of "key" in the text, 0 if none:
// points a message at a plane's field in a file written one field per line.
int LineOfKey(const std::string& text, const std::string& key, std::size_t occurrence) {
  const std::string quoted = "\"" + key + "\"";
  std::size_t at = text.find(quoted);
  for (std::size_t k = 0; k < occurrence && at != std::string::npos; ++k) {
    at = text.find(quoted, at + quoted.size());
  }
  return at == std::string::npos ? 0 : LineOfByte(text, at);
}

// A plane's "sigma" object: positive finite offset and normal sigmas, a unit major axis in the
// plane.
PlaneSigma ReadSigma(const PlaneReader& reader, const Eigen::Vector3d& normal, int line) {
  const char* fix =
      "sigma is {\"offset\": metres > 0, \"normal\": [radians > 0, radians > 0], "
      "\"major_axis\": unit vector in the plane}; regenerate with `planeloc map planes`";
  const auto fail = [&](const std::string& what) { reader.FailAt(line, what, fix); };
  const auto positive = [&](const json& value, const std::string& field) {
    if (!value.is_number()) fail(fmt::format("`{}` is not a number", field));
    const double number = value.get<double>();
    if (!(std::isfinite(number) && number > 0)) {
      fail(fmt::format("`{}` is {}, must be positive and finite", field, number));
    }
    return number;
  };
  const json& object = reader["sigma"];
  if (!object.is_object()) fail("`sigma` is not an object");
  for (const char* field : {"offset", "normal", "major_axis"}) {
    if (!object.contains(field)) fail(fmt::format("`sigma` has no `{}`", field));
  }
  PlaneSigma sigma;
  sigma.offset = positive(object["offset"], "sigma.offset");
  const json& tilt = object["normal"];
  if (!tilt.is_array() || tilt.size() != 2) fail("`sigma.normal` must be an array of 2 numbers");
  sigma.normal =
      Eigen::Vector2d(positive(tilt[0], "sigma.normal"), positive(tilt[1], "sigma.normal"));
  const json& axis = object["major_axis"];
  if (!axis.is_array() || axis.size() != 3 || !axis[0].is_number() || !axis[1].is_number() ||
      !axis[2].is_number()) {
    fail("`sigma.major_axis` must be an array of 3 numbers");
  }
  sigma.major_axis =
      Eigen::Vector3d(axis[0].get<double>(), axis[1].get<double>(), axis[2].get<double>());
  if (!sigma.major_axis.allFinite() || std::abs(sigma.major_axis.norm() - 1.0) > kNormalTolerance ||
      std::abs(sigma.major_axis.dot(normal)) > kNormalTolerance) {
    fail("`sigma.major_axis` must be a unit vector in the plane (perpendicular to normal)");
  }
  return sigma;
}

// sigmas_before: how many planes before this one have a sigma (to find its line in `text`).
MapPlane ReadMapPlane(const std::string& path, const std::string& text, const json& object,
                      std::size_t index, std::size_t sigmas_before) {
  const PlaneReader reader(path, object, fmt::format("plane {} (0-based)", index));
  if (!object.is_object()) reader.Fail("is not a JSON object");
  MapPlane plane;
  // Without an id a plane is numbered by its position, so ids stay unique.
  plane.id = reader.Integer("id", static_cast<int>(index));
  plane.plane_in_map = reader.ReadPlane();
  if (reader.Has("kind")) {
    if (!reader["kind"].is_string()) reader.Fail("`kind` is not a string");
    plane.kind = reader["kind"].get<std::string>();
  }
  if (reader.Has("centroid")) plane.centroid = reader.Vector(reader["centroid"], "centroid");
  plane.inliers = reader.Integer("inliers", 0);
  if (plane.inliers < 0) reader.Fail("`inliers` is negative");
  plane.rms = reader.OptionalNumber("rms");
  plane.area = reader.OptionalNumber("area");
  if (plane.rms < 0 || plane.area < 0) reader.Fail("`rms` and `area` must be >= 0");
  if (reader.Has("polygon")) {
    if (!reader["polygon"].is_array()) reader.Fail("`polygon` is not an array");
    for (const json& vertex : reader["polygon"]) {
      plane.polygon.push_back(reader.Vector(vertex, "polygon vertex"));
    }
  }
  if (reader.Has("sigma")) {
    plane.sigma =
        ReadSigma(reader, plane.plane_in_map.normal, LineOfKey(text, "sigma", sigmas_before));
  }
  if (reader.Has("provenance")) {
    if (!reader["provenance"].is_array()) reader.Fail("`provenance` is not an array");
    plane.provenance = reader["provenance"];
  }
  return plane;
}

// Every plane has a sigma or none has (then the defaults, and sigma_defaulted); a plane without
// one among planes with one is an error naming it and its line.
void CheckOrDefaultSigmas(const std::string& path, const std::string& text, PlaneMap& map) {
  std::size_t with_sigma = 0;
  for (const MapPlane& plane : map.planes) with_sigma += plane.sigma.known();
  if (with_sigma == map.planes.size()) return;
  if (with_sigma == 0) {
    for (MapPlane& plane : map.planes) {
      const Eigen::Vector3d& n = plane.plane_in_map.normal;
      plane.sigma.offset = kDefaultPlaneOffsetSigma;
      plane.sigma.normal.setConstant(kDefaultPlaneNormalSigma);
      plane.sigma.major_axis = n.unitOrthogonal();
    }
    map.sigma_defaulted = !map.planes.empty();
    return;
  }
  for (std::size_t i = 0; i < map.planes.size(); ++i) {
    if (map.planes[i].sigma.known()) continue;
    throw InputError(
        path, LineOfKey(text, "id", i),
        fmt::format("plane {} (0-based, id {}) has no `sigma` while {} of the {} planes have one",
                    i, map.planes[i].id, with_sigma, map.planes.size()),
        "give every plane a sigma (regenerate with `planeloc map planes`) or none (the defaults)");
  }
}

json VectorJson(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }

PlaneMapFrame ReadFrame(const std::string& path, const json& object) {
  const PlaneReader reader(path, object, "frame");
  if (!object.is_object()) reader.Fail("is not a JSON object");
  PlaneMapFrame frame;
  for (const char* field : {"name", "map", "up_source"}) {
    if (reader.Has(field) && !reader[field].is_string()) {
      reader.Fail(fmt::format("`{}` is not a string", field));
    }
  }
  if (reader.Has("name")) frame.name = reader["name"].get<std::string>();
  if (reader.Has("map")) frame.map_file = reader["map"].get<std::string>();
  if (reader.Has("up_source")) frame.up_source = reader["up_source"].get<std::string>();
  if (reader.Has("up")) {
    frame.up = reader.Vector(reader["up"], "up");
    if (std::abs(frame.up.norm() - 1.0) > kNormalTolerance) {
      reader.Fail(fmt::format("|up| = {:.6g}, expected 1", frame.up.norm()));
    }
  }
  if (frame.name.empty()) frame.name = "map";  // a frame object without a name is still known
  return frame;
}

}  // namespace

PlaneMap ReadPlaneMap(const std::filesystem::path& path) {
  std::ifstream stream(path);
  CheckInput(stream.good(), path.string(), 0, "plane map missing or unreadable",
             "build it with `planeloc map` or pass the right --planes path");
  const std::string text((std::istreambuf_iterator<char>(stream)),
                         std::istreambuf_iterator<char>());
  const json document = ParseJsonText(path.string(), text, "fix the JSON syntax");
  CheckInput(document.is_object() && document.contains("planes") && document["planes"].is_array(),
             path.string(), 0, "no `planes` array at the top level", kSchemaFix);
  PlaneMap map;
  std::set<int> ids;
  std::size_t sigmas = 0;
  for (std::size_t i = 0; i < document["planes"].size(); ++i) {
    map.planes.push_back(ReadMapPlane(path.string(), text, document["planes"][i], i, sigmas));
    sigmas += map.planes.back().sigma.known();
    CheckInput(ids.insert(map.planes.back().id).second, path.string(), 0,
               fmt::format("plane {} (0-based) repeats id {}", i, map.planes.back().id),
               "plane ids must be unique");
  }
  CheckOrDefaultSigmas(path.string(), text, map);
  if (document.contains("stats") && !document["stats"].is_null()) {
    CheckInput(document["stats"].is_object(), path.string(), 0, "`stats` is not an object",
               kSchemaFix);
    map.stats = document["stats"];
  }
  if (document.contains("frame") && !document["frame"].is_null()) {
    map.frame = ReadFrame(path.string(), document["frame"]);
  }
  map.source = path;
  return map;
}

void WritePlaneMap(const std::filesystem::path& path, const PlaneMap& map) {
  json planes = json::array();
  for (const MapPlane& plane : map.planes) {
    json polygon = json::array();
    for (const Eigen::Vector3d& vertex : plane.polygon) polygon.push_back(VectorJson(vertex));
    planes.push_back({{"id", plane.id},
                      {"kind", plane.kind},
                      {"normal", VectorJson(plane.plane_in_map.normal)},
                      {"d", plane.plane_in_map.d},
                      {"centroid", VectorJson(plane.centroid)},
                      {"inliers", plane.inliers},
                      {"rms", plane.rms},
                      {"area", plane.area},
                      {"polygon", polygon}});
    if (plane.sigma.known()) {
      planes.back()["sigma"] = {
          {"offset", plane.sigma.offset},
          {"normal", json::array({plane.sigma.normal.x(), plane.sigma.normal.y()})},
          {"major_axis", VectorJson(plane.sigma.major_axis)}};
    }
    if (!plane.provenance.empty()) planes.back()["provenance"] = plane.provenance;
  }
  json document = {{"planes", planes}, {"stats", map.stats}};
  if (map.frame.known()) {
    document["frame"] = {{"name", map.frame.name},
                         {"map", map.frame.map_file},
                         {"up", VectorJson(map.frame.up)},
                         {"up_source", map.frame.up_source}};
  }
  // nlohmann writes doubles with max_digits10, so a read-back is bit-exact.
  WriteFileWhole(path, document.dump(2) + '\n');
}

}  // namespace planeloc
