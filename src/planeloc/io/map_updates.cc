#include "planeloc/io/map_updates.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>

#include "planeloc/io/json_text.h"
#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

namespace planeloc {
namespace {

using nlohmann::json;

constexpr const char* kFormat = "planeloc map updates 1";
constexpr const char* kFix = "write it again with `planeloc run --map-update` (docs/map-update.md)";

// Line of the `occurrence`-th "id" key: the plane entry's first line as written.
int LineOfEntry(const std::string& text, std::size_t occurrence) {
  std::size_t at = text.find("\"id\"");
  for (std::size_t k = 0; k < occurrence && at != std::string::npos; ++k) {
    at = text.find("\"id\"", at + 4);
  }
  return at == std::string::npos ? 0 : LineOfByte(text, at);
}

json Vector2Json(const Eigen::Vector2d& v) { return json::array({v.x(), v.y()}); }

class EntryReader {
 public:
  EntryReader(const std::string& path, int line, const json& object, std::size_t index)
      : path_(path), line_(line), object_(object), index_(index) {}

  [[noreturn]] void Fail(const std::string& what) const {
    throw InputError(path_, line_, fmt::format("plane entry {} (0-based): {}", index_, what), kFix);
  }
  const json& Field(const char* name) const {
    if (!object_.contains(name)) Fail(fmt::format("no `{}`", name));
    return object_[name];
  }
  int Integer(const char* name) const {
    const json& value = Field(name);
    if (!value.is_number_integer()) Fail(fmt::format("`{}` is not an integer", name));
    return value.get<int>();
  }
  double Number(const json& value, const std::string& name) const {
    if (!value.is_number()) Fail(fmt::format("`{}` is not a number", name));
    const double number = value.get<double>();
    if (!std::isfinite(number)) Fail(fmt::format("`{}` is not finite", name));
    return number;
  }
  double Positive(const json& value, const std::string& name) const {
    const double number = Number(value, name);
    if (!(number > 0)) Fail(fmt::format("`{}` is {}, must be positive", name, number));
    return number;
  }
  template <int N>
  Eigen::Matrix<double, N, 1> Vector(const char* name, bool positive) const {
    const json& value = Field(name);
    if (!value.is_array() || value.size() != N) {
      Fail(fmt::format("`{}` must be an array of {} numbers", name, N));
    }
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v[i] = positive ? Positive(value[i], name) : Number(value[i], name);
    return v;
  }

 private:
  const std::string& path_;
  int line_;
  const json& object_;
  std::size_t index_;
};

PlaneUpdateStatus ParseStatus(const EntryReader& reader, const json& value) {
  if (value.is_string()) {
    const std::string text = value.get<std::string>();
    for (const PlaneUpdateStatus status :
         {PlaneUpdateStatus::kUnseen, PlaneUpdateStatus::kConfirmed, PlaneUpdateStatus::kCorrected,
          PlaneUpdateStatus::kContradicted}) {
      if (text == ToString(status)) return status;
    }
  }
  reader.Fail("`status` must be one of unseen, confirmed, corrected, contradicted");
}

}  // namespace

Eigen::Vector3d TiltedNormal(const Eigen::Vector3d& normal, const Eigen::Vector3d& e1,
                             const Eigen::Vector2d& tilt) {
  const Eigen::Vector3d e2 = normal.cross(e1).normalized();
  return (normal - tilt[0] * e2 + tilt[1] * e1).normalized();
}

const char* ToString(PlaneUpdateStatus status) {
  switch (status) {
    case PlaneUpdateStatus::kUnseen:
      return "unseen";
    case PlaneUpdateStatus::kConfirmed:
      return "confirmed";
    case PlaneUpdateStatus::kCorrected:
      return "corrected";
    case PlaneUpdateStatus::kContradicted:
      return "contradicted";
  }
  return "unseen";
}

std::string FileHash(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  CheckInput(stream.good(), path.string(), 0, "cannot read the file to hash it",
             "check that the path exists and is readable");
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  char buffer[1 << 16];
  while (stream) {
    stream.read(buffer, sizeof(buffer));
    for (std::streamsize i = 0; i < stream.gcount(); ++i) {
      hash ^= static_cast<unsigned char>(buffer[i]);
      hash *= 0x100000001b3ULL;
    }
  }
  CheckInput(stream.eof(), path.string(), 0, "read error while hashing the file",
             "check the file system");
  return fmt::format("{:016x}", hash);
}

void WriteMapUpdates(const std::filesystem::path& path, const MapUpdates& updates) {
  json planes = json::array();
  for (const PlaneUpdate& plane : updates.planes) {
    json entry = {{"id", plane.id},
                  {"status", ToString(plane.status)},
                  {"points", plane.points},
                  {"through", plane.through},
                  {"frames", plane.frames},
                  {"disabled_at_frame",
                   plane.disabled_at_frame ? json(*plane.disabled_at_frame) : json(nullptr)}};
    if (plane.measured()) {
      entry["offset"] = plane.offset;
      entry["offset_sigma"] = plane.offset_sigma;
      entry["tilt"] = Vector2Json(plane.tilt);
      entry["tilt_sigma"] = Vector2Json(plane.tilt_sigma);
      entry["normal"] = json::array({plane.normal.x(), plane.normal.y(), plane.normal.z()});
      entry["d"] = plane.d;
    }
    planes.push_back(std::move(entry));
  }
  const json document = {{"format", kFormat},
                         {"planes_file",
                          {{"path", updates.planes_path.string()},
                           {"fnv1a64", updates.planes_hash},
                           {"planes", updates.planes_count},
                           {"frame", updates.frame_name}}},
                         {"run",
                          {{"sequence", updates.sequence},
                           {"frames", updates.frames},
                           {"trajectory", updates.trajectory}}},
                         {"planes", planes}};
  WriteFileWhole(path, document.dump(1) + '\n');
}

MapUpdates ReadMapUpdates(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::ifstream stream(path);
  CheckInput(stream.good(), name, 0, "map updates file missing or unreadable",
             "pass the file `planeloc run --map-update` wrote");
  const std::string text((std::istreambuf_iterator<char>(stream)),
                         std::istreambuf_iterator<char>());
  const json document = ParseJsonText(name, text, kFix);
  CheckInput(document.is_object() && document.value("format", json()) == kFormat, name, 0,
             fmt::format("not a map updates file (no \"format\": \"{}\")", kFormat), kFix);
  MapUpdates updates;
  updates.source = path;
  try {
    const json& file = document.at("planes_file");
    updates.planes_path = file.at("path").get<std::string>();
    updates.planes_hash = file.at("fnv1a64").get<std::string>();
    updates.planes_count = file.at("planes").get<int>();
    updates.frame_name = file.at("frame").get<std::string>();
    const json& run = document.at("run");
    updates.sequence = run.at("sequence").get<std::string>();
    updates.frames = run.at("frames").get<int>();
    updates.trajectory = run.at("trajectory").get<std::string>();
  } catch (const json::exception& error) {
    throw InputError(name, fmt::format("`planes_file` or `run` is malformed: {}", error.what()),
                     kFix);
  }
  CheckInput(document.contains("planes") && document["planes"].is_array(), name, 0,
             "no `planes` array", kFix);
  std::set<int> ids;
  const json& entries = document["planes"];
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const json& object = entries[i];
    const EntryReader reader(name, LineOfEntry(text, i), object, i);
    if (!object.is_object()) reader.Fail("is not a JSON object");
    PlaneUpdate plane;
    plane.id = reader.Integer("id");
    if (!ids.insert(plane.id).second) reader.Fail(fmt::format("repeats plane id {}", plane.id));
    plane.status = ParseStatus(reader, reader.Field("status"));
    plane.points = reader.Integer("points");
    plane.through = reader.Integer("through");
    if (plane.points < 0 || plane.through < 0) reader.Fail("`points` and `through` must be >= 0");
    const json& frames = reader.Field("frames");
    if (!frames.is_array()) reader.Fail("`frames` is not an array");
    for (const json& frame : frames) {
      if (!frame.is_number_integer()) reader.Fail("`frames` holds a non-integer");
      plane.frames.push_back(frame.get<int>());
    }
    if (object.contains("disabled_at_frame") && !object["disabled_at_frame"].is_null()) {
      plane.disabled_at_frame = reader.Integer("disabled_at_frame");
    }
    if (plane.measured()) {
      plane.offset = reader.Number(reader.Field("offset"), "offset");
      plane.offset_sigma = reader.Positive(reader.Field("offset_sigma"), "offset_sigma");
      plane.tilt = reader.Vector<2>("tilt", false);
      plane.tilt_sigma = reader.Vector<2>("tilt_sigma", true);
      plane.normal = reader.Vector<3>("normal", false);
      if (std::abs(plane.normal.norm() - 1.0) > 1e-3) reader.Fail("`normal` is not a unit vector");
      plane.d = reader.Number(reader.Field("d"), "d");
    }
    updates.planes.push_back(std::move(plane));
  }
  return updates;
}

}  // namespace planeloc
