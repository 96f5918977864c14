// Hand-made .pcd and .ply files for the reader tests, written byte by byte from the specs
// (pointclouds.org PCD v0.7, paulbourke.net PLY), independently of the readers under test.
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace planeloc::testing {

// Appends the little- (or big-) endian bytes of `value` as type T.
template <typename T>
void Put(std::string& bytes, T value, bool big_endian = false) {
  char buffer[sizeof(T)];
  std::memcpy(buffer, &value, sizeof(T));
  if (big_endian) std::reverse(buffer, buffer + sizeof(T));
  bytes.append(buffer, sizeof(T));
}

// Literal-only LZF stream (control byte n - 1 before each run of n <= 32 bytes): valid LZF that
// any decoder must accept.
inline std::string LzfLiterals(const std::string& raw) {
  std::string out;
  for (std::size_t k = 0; k < raw.size(); k += 32) {
    const std::size_t n = std::min<std::size_t>(32, raw.size() - k);
    out.push_back(static_cast<char>(n - 1));
    out.append(raw, k, n);
  }
  return out;
}

// The points of every fixture: distinct, non-round coordinates (exact in float32 only where the
// test says so).
inline std::vector<Eigen::Vector3d> FixturePoints() {
  return {{1.5, -2.25, 3.125}, {-4.0625, 0.5, 7.75},   {100.123456789012, -200.5, 0.001},
          {0.0, 0.0, -1.5},    {12.5, 13.25, -14.375}, {-0.75, 8.0, 2.0}};
}

struct PcdFixture {
  std::string data = "binary";  // ascii | binary | binary_compressed
  bool float64 = false;         // x y z as F 8 instead of F 4
  bool extras = true;           // intensity F4, ring U2, rgb U4 (packed), normals F4 x3 (COUNT 3)
  int width = 6, height = 1;    // organized when height > 1
  std::vector<Eigen::Vector3d> points = FixturePoints();
};

// Field table: name, TYPE, SIZE, COUNT.
struct PcdFieldSpec {
  const char* name;
  char type;
  int size;
  int count;
};

inline std::vector<PcdFieldSpec> PcdFields(const PcdFixture& f) {
  const int s = f.float64 ? 8 : 4;
  if (!f.extras) return {{"x", 'F', s, 1}, {"y", 'F', s, 1}, {"z", 'F', s, 1}};
  // intensity before x (as some drivers write), a multi-value field and PCL padding.
  return {{"intensity", 'F', 4, 1}, {"x", 'F', s, 1},    {"y", 'F', s, 1},
          {"z", 'F', s, 1},         {"ring", 'U', 2, 1}, {"rgb", 'U', 4, 1},
          {"normal", 'F', 4, 3},    {"time", 'F', 8, 1}, {"_", 'U', 1, 4}};
}

// Bytes of field `spec` (element `c`) of point i.
inline std::string PcdValue(const PcdFieldSpec& spec, const Eigen::Vector3d& p, std::size_t i,
                            int c) {
  std::string bytes;
  const std::string name = spec.name;
  double value = 0.25 * static_cast<double>(i) + c;
  if (name == "x" || name == "y" || name == "z") value = p[name[0] - 'x'];
  if (name == "rgb") {
    Put<std::uint32_t>(bytes, 0x00ff8000u + static_cast<std::uint32_t>(i));
    return bytes;
  }
  if (spec.type == 'F' && spec.size == 4) Put<float>(bytes, static_cast<float>(value));
  if (spec.type == 'F' && spec.size == 8) Put<double>(bytes, value);
  if (spec.type == 'U' && spec.size == 1) Put<std::uint8_t>(bytes, static_cast<std::uint8_t>(i));
  if (spec.type == 'U' && spec.size == 2) Put<std::uint16_t>(bytes, static_cast<std::uint16_t>(i));
  return bytes;
}

inline std::string PcdAsciiValue(const PcdFieldSpec& spec, const Eigen::Vector3d& p, std::size_t i,
                                 int c) {
  const std::string name = spec.name;
  char text[64];
  if (name == "x" || name == "y" || name == "z") {
    std::snprintf(text, sizeof(text), "%.17g", p[name[0] - 'x']);
  } else if (name == "rgb") {
    std::snprintf(text, sizeof(text), "%u", 0x00ff8000u + static_cast<unsigned>(i));
  } else {
    std::snprintf(text, sizeof(text), "%g", 0.25 * static_cast<double>(i) + c);
  }
  return text;
}

inline std::string PcdHeaderText(const PcdFixture& f, const std::vector<PcdFieldSpec>& fields) {
  std::string names, sizes, types, counts;
  for (const auto& spec : fields) {
    names += std::string(" ") + spec.name;
    sizes += " " + std::to_string(spec.size);
    types += std::string(" ") + spec.type;
    counts += " " + std::to_string(spec.count);
  }
  return "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS" + names + "\nSIZE" +
         sizes + "\nTYPE" + types + "\nCOUNT" + counts + "\nWIDTH " + std::to_string(f.width) +
         "\nHEIGHT " + std::to_string(f.height) + "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " +
         std::to_string(f.points.size()) + "\nDATA " + f.data + "\n";
}

inline std::string PcdBody(const PcdFixture& f, const std::vector<PcdFieldSpec>& fields) {
  std::string body;
  if (f.data == "ascii") {
    for (std::size_t i = 0; i < f.points.size(); ++i) {
      std::string line;
      for (const auto& spec : fields) {
        for (int c = 0; c < spec.count; ++c) {
          if (!line.empty()) line += ' ';
          line += PcdAsciiValue(spec, f.points[i], i, c);
        }
      }
      body += line + "\n";
    }
  } else if (f.data == "binary") {
    for (std::size_t i = 0; i < f.points.size(); ++i) {
      for (const auto& spec : fields) {
        for (int c = 0; c < spec.count; ++c) body += PcdValue(spec, f.points[i], i, c);
      }
    }
  } else {  // binary_compressed: all values of a field, then the next field
    std::string raw;
    for (const auto& spec : fields) {
      for (std::size_t i = 0; i < f.points.size(); ++i) {
        for (int c = 0; c < spec.count; ++c) raw += PcdValue(spec, f.points[i], i, c);
      }
    }
    const std::string packed = LzfLiterals(raw);
    Put<std::uint32_t>(body, static_cast<std::uint32_t>(packed.size()));
    Put<std::uint32_t>(body, static_cast<std::uint32_t>(raw.size()));
    body += packed;
  }
  return body;
}

inline std::string PcdFile(const PcdFixture& f) {
  const auto fields = PcdFields(f);
  return PcdHeaderText(f, fields) + PcdBody(f, fields);
}

struct PlyFixture {
  std::string format = "binary_little_endian";  // | ascii | binary_big_endian
  bool float64 = false;                         // x y z as double
  bool extras = true;  // nx ny nz (float), intensity (ushort), red green blue (uchar), + 1 face
  std::vector<Eigen::Vector3d> points = FixturePoints();
};

inline std::string PlyFile(const PlyFixture& f) {
  const bool big = f.format == "binary_big_endian";
  const char* coord = f.float64 ? "double" : "float";
  std::string text = "ply\nformat " + f.format + " 1.0\ncomment planeloc test fixture\n" +
                     "element vertex " + std::to_string(f.points.size()) + "\n";
  text +=
      std::string("property ") + coord + " x\nproperty " + coord + " y\nproperty " + coord + " z\n";
  if (f.extras) {
    text +=
        "property float nx\nproperty float ny\nproperty float nz\nproperty ushort intensity\n"
        "property uchar red\nproperty uchar green\nproperty uchar blue\n"
        "element face 1\nproperty list uchar int vertex_indices\n";
  }
  text += "end_header\n";
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    const Eigen::Vector3d& p = f.points[i];
    if (f.format == "ascii") {
      char line[256];
      std::snprintf(line, sizeof(line), "%.17g %.17g %.17g", p.x(), p.y(), p.z());
      text += line;
      if (f.extras)
        text += " 0 0 1 " + std::to_string(100 * i) + " 255 " + std::to_string(i) + " 0";
      text += "\n";
      continue;
    }
    for (int k = 0; k < 3; ++k) {
      if (f.float64) {
        Put<double>(text, p[k], big);
      } else {
        Put<float>(text, static_cast<float>(p[k]), big);
      }
    }
    if (f.extras) {
      Put<float>(text, 0.f, big);
      Put<float>(text, 0.f, big);
      Put<float>(text, 1.f, big);
      Put<std::uint16_t>(text, static_cast<std::uint16_t>(100 * i), big);
      Put<std::uint8_t>(text, 255);
      Put<std::uint8_t>(text, static_cast<std::uint8_t>(i));
      Put<std::uint8_t>(text, 0);
    }
  }
  if (f.extras) {
    if (f.format == "ascii") {
      text += "3 0 1 2\n";
    } else {
      Put<std::uint8_t>(text, 3);
      for (std::int32_t v : {0, 1, 2}) Put<std::int32_t>(text, v, big);
    }
  }
  return text;
}

}  // namespace planeloc::testing
