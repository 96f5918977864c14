#include "planeloc/io/ply_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <climits>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "planeloc/io/scalar_field.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr const char* kFixHeader =
    "the header does not describe the data: re-save the cloud with its tool (Open3D, "
    "CloudCompare, MeshLab)";

struct PlyProperty {
  std::string name;
  ScalarType type;
  bool list = false;
  std::size_t offset = 0;  // bytes from the start of a record (fixed-size elements)
};

struct PlyElement {
  std::string name;
  long long count = 0;
  int line = 0;
  std::vector<PlyProperty> properties;
  bool has_list = false;
  std::size_t size = 0;  // bytes of one record when !has_list
};

bool ParseType(const std::string& name, ScalarType& type) {
  static const std::map<std::string, ScalarType> kTypes = {
      {"char", {ScalarKind::kInt, 1}},     {"int8", {ScalarKind::kInt, 1}},
      {"uchar", {ScalarKind::kUint, 1}},   {"uint8", {ScalarKind::kUint, 1}},
      {"short", {ScalarKind::kInt, 2}},    {"int16", {ScalarKind::kInt, 2}},
      {"ushort", {ScalarKind::kUint, 2}},  {"uint16", {ScalarKind::kUint, 2}},
      {"int", {ScalarKind::kInt, 4}},      {"int32", {ScalarKind::kInt, 4}},
      {"uint", {ScalarKind::kUint, 4}},    {"uint32", {ScalarKind::kUint, 4}},
      {"float", {ScalarKind::kFloat, 4}},  {"float32", {ScalarKind::kFloat, 4}},
      {"double", {ScalarKind::kFloat, 8}}, {"float64", {ScalarKind::kFloat, 8}}};
  const auto it = kTypes.find(name);
  if (it == kTypes.end()) return false;
  type = it->second;
  return true;
}

// Colour channel in [0, 1]: integers scaled by their maximum, floats as they are.
double ColorChannel(double value, ScalarType type) {
  if (type.kind == ScalarKind::kFloat) return value;
  return value / (type.size == 1 ? 255.0 : 65535.0);
}

class PlyReader {
 public:
  PlyReader(const std::filesystem::path& path, VoxelAccumulator& sink,
            std::vector<std::string>* comments)
      : path_(path), name_(path.string()), sink_(sink), comments_(comments) {}

  void Read() {
    std::ifstream stream(path_, std::ios::binary);
    CheckInput(stream.good(), name_, 0, "cannot open the point cloud",
               "check the path and permissions");
    ReadHeader(stream);
    Validate();
    if (format_ == "ascii") {
      ReadAscii(stream);
    } else {
      ReadBinary(stream);
    }
  }

 private:
  [[noreturn]] void Fail(int line, const std::string& what, const std::string& fix) const {
    throw InputError(name_, line, what, fix);
  }

  void ReadHeader(std::istream& stream) {
    std::string line;
    int number = 0;
    while (std::getline(stream, line)) {
      ++number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      std::istringstream split(line);
      std::vector<std::string> tokens;
      for (std::string token; split >> token;) tokens.push_back(token);
      if (number == 1) {
        CheckInput(tokens.size() == 1 && tokens[0] == "ply", name_, 1,
                   "not a .ply file (the first line is not 'ply')",
                   "check the file is a PLY point cloud");
        continue;
      }
      if (!tokens.empty() && tokens[0] == "comment" && comments_) {
        const std::size_t text = line.find_first_not_of(" \t", line.find("comment") + 7);
        comments_->push_back(text == std::string::npos ? "" : line.substr(text));
      }
      if (tokens.empty() || tokens[0] == "comment" || tokens[0] == "obj_info") continue;
      if (tokens[0] == "end_header") {
        header_lines_ = number;
        data_offset_ = stream.tellg();
        return;
      }
      if (tokens[0] == "format") {
        if (tokens.size() != 3 || (tokens[1] != "ascii" && tokens[1] != "binary_little_endian" &&
                                   tokens[1] != "binary_big_endian")) {
          Fail(number, "unknown PLY format line '" + line + "'",
               "use ascii, binary_little_endian or binary_big_endian");
        }
        format_ = tokens[1];
      } else if (tokens[0] == "element") {
        long long count = -1;
        if (tokens.size() == 3) {
          const auto [end, error] =
              std::from_chars(tokens[2].data(), tokens[2].data() + tokens[2].size(), count);
          if (error != std::errc() || end != tokens[2].data() + tokens[2].size()) count = -1;
        }
        if (count < 0) Fail(number, "malformed element line '" + line + "'", kFixHeader);
        elements_.push_back({tokens[1], count, number, {}, false, 0});
      } else if (tokens[0] == "property") {
        if (elements_.empty()) Fail(number, "property before any element", kFixHeader);
        PlyElement& element = elements_.back();
        PlyProperty property;
        ScalarType item_type;
        const bool list = tokens.size() == 5 && tokens[1] == "list";
        if (list) {
          // Only the count's type is kept: list elements are skipped, never decoded.
          if (!ParseType(tokens[2], property.type) || property.type.kind == ScalarKind::kFloat ||
              !ParseType(tokens[3], item_type)) {
            Fail(number, "unknown list types in '" + line + "'", kFixHeader);
          }
        } else if (tokens.size() != 3 || !ParseType(tokens[1], property.type)) {
          Fail(number, "unknown property type in '" + line + "'",
               "use char, uchar, short, ushort, int, uint, float or double (or int8 ... float64)");
        }
        property.name = tokens.back();
        property.list = list;
        property.offset = element.size;
        element.has_list = element.has_list || list;
        element.size += static_cast<std::size_t>(property.type.size);
        element.properties.push_back(property);
      } else {
        Fail(number, "unknown PLY header line '" + line + "'", kFixHeader);
      }
    }
    Fail(0, "not a .ply file (no end_header line)", "check the file is a PLY point cloud");
  }

  void Validate() {
    CheckInput(!format_.empty(), name_, 0, "the .ply header has no format line", kFixHeader);
    for (std::size_t e = 0; e < elements_.size(); ++e) {
      if (elements_[e].name == "vertex") {
        vertex_ = static_cast<int>(e);
        break;
      }
    }
    CheckInput(vertex_ >= 0, name_, 0, "the .ply has no vertex element",
               "write the points as a `vertex` element with x y z");
    const PlyElement& vertex = elements_[vertex_];
    CheckInput(vertex.count > 0, name_, vertex.line, "the point cloud is empty (0 points)",
               "give a map with points (e.g. from `planeloc map build`)");
    CheckInput(!vertex.has_list, name_, vertex.line,
               "list properties in the vertex element are not supported",
               "write the vertices with scalar properties only");
    for (int e = 0; e < vertex_; ++e) {
      CheckInput(!elements_[e].has_list || format_ == "ascii", name_, elements_[e].line,
                 "binary elements with list properties before `vertex` are not supported",
                 "write the vertex element first");
    }
    for (std::size_t p = 0; p < vertex.properties.size(); ++p) {
      const std::string& name = vertex.properties[p].name;
      const int index = static_cast<int>(p);
      if (name == "x") x_ = index;
      if (name == "y") y_ = index;
      if (name == "z") z_ = index;
      if (name == "red") red_ = index;
      if (name == "green") green_ = index;
      if (name == "blue") blue_ = index;
    }
    CheckInput(x_ >= 0 && y_ >= 0 && z_ >= 0, name_, vertex.line,
               "the vertex element has no x, y and z properties",
               "write the point coordinates as x y z");
    if (red_ < 0 || green_ < 0 || blue_ < 0) red_ = -1;
  }

  void Emit(const Eigen::Vector3d& point, const Eigen::Vector3d& color, long long index) {
    CheckInput(point.allFinite(), name_, 0,
               fmt::format("point {} has a NaN or infinite coordinate", index),
               "remove invalid points from the map before processing it");
    sink_.Add(point, red_ >= 0 ? &color : nullptr);
  }

  void ReadAscii(std::istream& stream) {
    std::string line;
    int number = header_lines_;
    std::vector<std::string> tokens;
    auto next_line = [&]() {
      while (std::getline(stream, line)) {
        ++number;
        std::istringstream split(line);
        tokens.clear();
        for (std::string token; split >> token;) tokens.push_back(token);
        if (!tokens.empty()) return true;
      }
      return false;
    };
    for (int e = 0; e < vertex_; ++e) {
      for (long long k = 0; k < elements_[e].count; ++k) {
        CheckInput(next_line(), name_, elements_[e].line,
                   fmt::format("element {} {} but the data ends after {}", elements_[e].name,
                               elements_[e].count, k),
                   kFixHeader);
      }
    }
    const PlyElement& vertex = elements_[vertex_];
    const std::uintmax_t file_size = std::filesystem::file_size(path_);
    sink_.Reserve(static_cast<std::size_t>(std::min<std::uintmax_t>(
        static_cast<std::uintmax_t>(vertex.count), file_size / (2 * vertex.properties.size()))));
    auto value = [&](int p) {
      const std::string& token = tokens[static_cast<std::size_t>(p)];
      char* end = nullptr;
      const double parsed = std::strtod(token.c_str(), &end);
      if (end != token.c_str() + token.size()) {
        Fail(number, fmt::format("{} '{}' is not a number", vertex.properties[p].name, token),
             "fix or re-save the file");
      }
      return parsed;
    };
    for (long long k = 0; k < vertex.count; ++k) {
      if (!next_line()) {
        Fail(vertex.line,
             fmt::format("element vertex {} but the data holds {} vertices", vertex.count, k),
             kFixHeader);
      }
      if (tokens.size() != vertex.properties.size()) {
        Fail(number,
             fmt::format("{} values on the line but the vertex element has {} properties",
                         tokens.size(), vertex.properties.size()),
             kFixHeader);
      }
      Eigen::Vector3d color = Eigen::Vector3d::Zero();
      if (red_ >= 0) {
        color = {ColorChannel(value(red_), vertex.properties[red_].type),
                 ColorChannel(value(green_), vertex.properties[green_].type),
                 ColorChannel(value(blue_), vertex.properties[blue_].type)};
      }
      Emit({value(x_), value(y_), value(z_)}, color, k);
    }
    long long rest = 0;
    for (std::size_t e = static_cast<std::size_t>(vertex_) + 1; e < elements_.size(); ++e) {
      // Saturated: counts up to 2^63 - 1 each would overflow the sum.
      rest = elements_[e].count > LLONG_MAX - rest ? LLONG_MAX : rest + elements_[e].count;
    }
    long long extra = 0;
    while (next_line()) ++extra;
    if (extra != rest) {
      Fail(vertex.line,
           fmt::format("the header's elements after the vertices hold {} lines, the data {} "
                       "(is the vertex count {} right?)",
                       rest, extra, vertex.count),
           kFixHeader);
    }
  }

  void ReadBinary(std::istream& stream) {
    const bool big_endian = format_ == "binary_big_endian";
    const std::uintmax_t file_size = std::filesystem::file_size(path_);
    const auto offset = static_cast<std::uintmax_t>(data_offset_);
    std::uintmax_t available = file_size > offset ? file_size - offset : 0;
    for (int e = 0; e < vertex_; ++e) {  // fixed-size elements before the vertices
      const PlyElement& element = elements_[e];
      const auto count = static_cast<std::uintmax_t>(element.count);
      CheckInput(count <= available / std::max<std::size_t>(element.size, 1), name_, element.line,
                 fmt::format("element {} {} does not fit in the file", element.name, count),
                 kFixHeader);
      stream.seekg(static_cast<std::streamoff>(count * element.size), std::ios::cur);
      available -= count * element.size;
    }
    const PlyElement& vertex = elements_[vertex_];
    const auto count = static_cast<std::uintmax_t>(vertex.count);
    const std::string need = count <= available / vertex.size
                                 ? std::to_string(count * vertex.size)
                                 : "more than " + std::to_string(available);
    CheckInput(count <= available / vertex.size, name_, vertex.line,
               fmt::format("element vertex {} x {} bytes a vertex = {} bytes, but the file holds "
                           "{} bytes of data",
                           vertex.count, vertex.size, need, available),
               kFixHeader);
    available -= count * vertex.size;
    // Fixed-size elements after the vertices (or none): the sizes must add up exactly.
    std::uintmax_t rest = 0;
    bool fixed = true;
    for (std::size_t e = static_cast<std::size_t>(vertex_) + 1; e < elements_.size(); ++e) {
      fixed = fixed && !elements_[e].has_list;
      rest += static_cast<std::uintmax_t>(elements_[e].count) * elements_[e].size;
    }
    if (fixed && rest != available) {
      Fail(vertex.line,
           fmt::format("the header's elements take {} bytes after the vertices, the file holds "
                       "{} (is the vertex count {} right?)",
                       rest, available, vertex.count),
           kFixHeader);
    }
    sink_.Reserve(static_cast<std::size_t>(count));
    const std::vector<PlyProperty>& props = vertex.properties;
    constexpr std::size_t kChunk = 1 << 16;
    // Never larger than the data (a vertex of many properties times kChunk is a lot).
    std::vector<unsigned char> buffer(std::min<std::uintmax_t>(kChunk, count) * vertex.size);
    for (std::uintmax_t first = 0; first < count; first += kChunk) {
      const std::size_t n =
          static_cast<std::size_t>(std::min<std::uintmax_t>(kChunk, count - first));
      stream.read(reinterpret_cast<char*>(buffer.data()),
                  static_cast<std::streamsize>(n * vertex.size));
      CheckInput(stream.good(), name_, 0, "read error in the vertex data",
                 "check the file is complete and readable");
      for (std::size_t i = 0; i < n; ++i) {
        const unsigned char* record = buffer.data() + i * vertex.size;
        auto get = [&](int p) {
          return DecodeScalar(record + props[p].offset, props[p].type, big_endian);
        };
        Eigen::Vector3d color = Eigen::Vector3d::Zero();
        if (red_ >= 0) {
          color = {ColorChannel(get(red_), props[red_].type),
                   ColorChannel(get(green_), props[green_].type),
                   ColorChannel(get(blue_), props[blue_].type)};
        }
        Emit({get(x_), get(y_), get(z_)}, color, static_cast<long long>(first + i));
      }
    }
  }

  std::filesystem::path path_;
  std::string name_;
  VoxelAccumulator& sink_;
  std::vector<std::string>* comments_;
  std::string format_;
  std::vector<PlyElement> elements_;
  int header_lines_ = 0;
  std::streamoff data_offset_ = 0;
  int vertex_ = -1;
  int x_ = -1, y_ = -1, z_ = -1, red_ = -1, green_ = -1, blue_ = -1;
};

}  // namespace

void ReadPly(const std::filesystem::path& path, VoxelAccumulator& sink,
             std::vector<std::string>* comments) {
  PlyReader(path, sink, comments).Read();
}

}  // namespace planeloc
