#include "planeloc/io/pcd_reader.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "planeloc/io/lzf.h"
#include "planeloc/io/scalar_field.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr const char* kFixHeader =
    "the header does not describe the data: re-save the cloud with its tool (PCL pcl::io::savePCD"
    "File, Open3D write_point_cloud, CloudCompare)";

struct PcdField {
  std::string name;
  ScalarType type;
  int count = 1;
  std::size_t offset = 0;  // bytes from the start of a point record
  std::size_t value = 0;   // index of its first value on an ascii line
};

struct PcdHeader {
  std::vector<std::string> names, sizes, types, counts;
  int fields_line = 0, size_line = 0, type_line = 0, count_line = 0;
  long long width = -1, height = 1, points = -1;
  int width_line = 0, height_line = 0, points_line = 0, data_line = 0;
  std::string data;
  std::streamoff data_offset = 0;
  // Derived by Validate():
  std::vector<PcdField> fields;
  std::size_t point_size = 0;            // bytes of one binary record
  std::size_t point_values = 0;          // values on one ascii line
  int x = -1, y = -1, z = -1, rgb = -1;  // field indices (rgb: -1 when absent)
};

class PcdReader {
 public:
  PcdReader(const std::filesystem::path& path, VoxelAccumulator& sink,
            std::vector<std::string>* comments)
      : path_(path), name_(path.string()), sink_(sink), comments_(comments) {}

  std::size_t Read() {
    std::ifstream stream(path_, std::ios::binary);
    CheckInput(stream.good(), name_, 0, "cannot open the point cloud",
               "check the path and permissions");
    ReadHeader(stream);
    Validate();
    organized_ = header_.height > 1;
    if (header_.data == "ascii") {
      ReadAscii(stream);
    } else {
      const std::uintmax_t file_size = std::filesystem::file_size(path_);
      const std::uintmax_t offset = static_cast<std::uintmax_t>(header_.data_offset);
      const std::uintmax_t data_bytes = file_size > offset ? file_size - offset : 0;
      if (header_.data == "binary") {
        ReadBinary(stream, data_bytes);
      } else {
        ReadCompressed(stream, data_bytes);
      }
    }
    return dropped_;
  }

 private:
  [[noreturn]] void Fail(int line, const std::string& what, const std::string& fix) const {
    throw InputError(name_, line, what, fix);
  }

  long long Count(const std::string& token, int line, const char* key) const {
    long long value = -1;
    const auto [end, error] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (error != std::errc() || end != token.data() + token.size() || value < 0) {
      Fail(line, fmt::format("{} '{}' is not a non-negative integer", key, token), kFixHeader);
    }
    return value;
  }

  void ReadHeader(std::istream& stream) {
    std::string line;
    int number = 0;
    while (std::getline(stream, line)) {
      ++number;
      if (!line.empty() && line.back() == '\r') line.pop_back();
      std::istringstream tokens(line);
      std::string key;
      if (!(tokens >> key)) continue;
      if (key[0] == '#') {
        if (comments_ && number > 1) {
          std::size_t text = line.find('#') + 1;
          if (text < line.size() && line[text] == ' ') ++text;
          comments_->push_back(line.substr(text));
        }
        continue;
      }
      std::vector<std::string> values;
      for (std::string value; tokens >> value;) values.push_back(value);
      auto single = [&](const char* what) {
        if (values.size() != 1) {
          Fail(number, fmt::format("{} needs one value, the line has {}", what, values.size()),
               kFixHeader);
        }
        return Count(values[0], number, what);
      };
      if (key == "VERSION" || key == "VIEWPOINT") continue;
      if (key == "FIELDS") {
        header_.names = values;
        header_.fields_line = number;
      } else if (key == "SIZE") {
        header_.sizes = values;
        header_.size_line = number;
      } else if (key == "TYPE") {
        header_.types = values;
        header_.type_line = number;
      } else if (key == "COUNT") {
        header_.counts = values;
        header_.count_line = number;
      } else if (key == "WIDTH") {
        header_.width = single("WIDTH");
        header_.width_line = number;
      } else if (key == "HEIGHT") {
        header_.height = single("HEIGHT");
        header_.height_line = number;
      } else if (key == "POINTS") {
        header_.points = single("POINTS");
        header_.points_line = number;
      } else if (key == "DATA") {
        header_.data = values.empty() ? "" : values[0];
        header_.data_line = number;
        header_.data_offset = stream.tellg();
        return;
      } else if (number == 1 && header_.names.empty()) {
        Fail(0, "not a .pcd file (it does not start with a PCD header)",
             "check the file is a PCL .pcd point cloud");
      } else {
        Fail(number, fmt::format("unknown .pcd header key '{}'", key), kFixHeader);
      }
    }
    Fail(0, "not a .pcd file (no DATA line in the header)",
         "check the file is a PCL .pcd point cloud");
  }

  void Validate() {
    PcdHeader& h = header_;
    CheckInput(!h.names.empty(), name_, 0, "not a .pcd file (no FIELDS line in the header)",
               "check the file is a PCL .pcd point cloud");
    const std::size_t n = h.names.size();
    auto same_count = [&](const std::vector<std::string>& values, int line, const char* key) {
      if (values.size() != n) {
        Fail(line,
             fmt::format("{} has {} entries but FIELDS has {} ({})", key, values.size(), n,
                         fmt::join(h.names, " ")),
             kFixHeader);
      }
    };
    CheckInput(h.size_line > 0 && h.type_line > 0, name_, h.fields_line,
               "the .pcd header has no SIZE or no TYPE line", kFixHeader);
    same_count(h.sizes, h.size_line, "SIZE");
    same_count(h.types, h.type_line, "TYPE");
    if (h.count_line > 0) same_count(h.counts, h.count_line, "COUNT");
    for (std::size_t f = 0; f < n; ++f) {
      PcdField field;
      field.name = h.names[f];
      const long long size = Count(h.sizes[f], h.size_line, "SIZE");
      const std::string& type = h.types[f];
      if (type != "F" && type != "I" && type != "U") {
        Fail(h.type_line,
             fmt::format("field '{}' has TYPE '{}' (expected F, I or U)", field.name, type),
             kFixHeader);
      }
      field.type.kind =
          type == "F" ? ScalarKind::kFloat : (type == "I" ? ScalarKind::kInt : ScalarKind::kUint);
      field.type.size = static_cast<int>(std::min(size, 64LL));
      if (!field.type.Valid()) {
        Fail(h.size_line,
             fmt::format("field '{}' has TYPE {} with SIZE {} (F takes 4 or 8 bytes, I and U take "
                         "1, 2, 4 or 8)",
                         field.name, type, size),
             kFixHeader);
      }
      const long long count = h.count_line > 0 ? Count(h.counts[f], h.count_line, "COUNT") : 1;
      if (count < 1 || count > 1'000'000) {
        Fail(h.count_line, fmt::format("field '{}' has COUNT {}", field.name, count), kFixHeader);
      }
      field.count = static_cast<int>(count);
      field.offset = h.point_size;
      field.value = h.point_values;
      h.point_size += static_cast<std::size_t>(field.type.size) * field.count;
      h.point_values += static_cast<std::size_t>(field.count);
      const int index = static_cast<int>(f);
      if (field.name == "x") h.x = index;
      if (field.name == "y") h.y = index;
      if (field.name == "z") h.z = index;
      if ((field.name == "rgb" || field.name == "rgba") && field.type.size == 4 && count == 1) {
        h.rgb = index;
      }
      h.fields.push_back(field);
    }
    CheckInput(h.x >= 0 && h.y >= 0 && h.z >= 0, name_, h.fields_line,
               "the .pcd has no x, y and z fields", "write the point coordinates as x y z");
    for (const int f : {h.x, h.y, h.z}) {
      CheckInput(h.fields[f].count == 1, name_, h.count_line,
                 fmt::format("field '{}' has COUNT {} (coordinates need 1)", h.fields[f].name,
                             h.fields[f].count),
                 kFixHeader);
    }
    CheckInput(h.width >= 0, name_, 0, "the .pcd header has no WIDTH line", kFixHeader);
    // The product too: two factors below 2^40 can overflow 64 bits.
    CheckInput(h.width <= (1LL << 40) && h.height <= (1LL << 40) &&
                   (h.height == 0 || h.width <= (1LL << 40) / h.height),
               name_, h.width_line,
               fmt::format("WIDTH {} x HEIGHT {} is absurdly large", h.width, h.height),
               kFixHeader);
    const long long cells = h.width * h.height;
    if (h.points < 0) {
      h.points = cells;  // POINTS is optional before v0.7
    } else if (h.points != cells) {
      Fail(h.points_line,
           fmt::format("WIDTH x HEIGHT = {} x {} = {} but POINTS is {}", h.width, h.height, cells,
                       h.points),
           kFixHeader);
    }
    CheckInput(h.points != 0, name_, h.points_line, "the point cloud is empty (0 points)",
               "give a map with points (e.g. from `planeloc map build`)");
    if (h.data != "ascii" && h.data != "binary" && h.data != "binary_compressed") {
      Fail(h.data_line,
           fmt::format("DATA '{}' (expected ascii, binary or binary_compressed)", h.data),
           kFixHeader);
    }
  }

  void Emit(const Eigen::Vector3d& point, std::uint32_t rgb, long long index) {
    if (!point.allFinite()) {
      if (organized_ && !point.array().isInf().any()) {
        ++dropped_;  // an organized cloud's "no return"
        return;
      }
      Fail(0, fmt::format("point {} has a NaN or infinite coordinate", index),
           "remove invalid points from the map before processing it");
    }
    if (header_.rgb < 0) {
      sink_.Add(point, nullptr);
      return;
    }
    const Eigen::Vector3d color((rgb >> 16) & 0xff, (rgb >> 8) & 0xff, rgb & 0xff);
    const Eigen::Vector3d unit = color / 255.0;
    sink_.Add(point, &unit);
  }

  void ReadAscii(std::istream& stream) {
    const PcdHeader& h = header_;
    const std::uintmax_t file_size = std::filesystem::file_size(path_);
    // At least two characters a value: never reserve more than the file can hold.
    sink_.Reserve(static_cast<std::size_t>(std::min<std::uintmax_t>(
        static_cast<std::uintmax_t>(h.points), file_size / (2 * h.point_values))));
    std::string line;
    std::vector<std::string> tokens;
    long long read = 0;
    int number = h.data_line;
    auto value = [&](int field) -> double {
      const std::string& token = tokens[h.fields[field].value];
      char* end = nullptr;
      const double parsed = std::strtod(token.c_str(), &end);
      if (end != token.c_str() + token.size()) {
        Fail(number, fmt::format("{} '{}' is not a number", h.fields[field].name, token),
             "fix or re-save the file");
      }
      return parsed;
    };
    while (std::getline(stream, line)) {
      ++number;
      std::istringstream split(line);
      tokens.clear();
      for (std::string token; split >> token;) tokens.push_back(token);
      if (tokens.empty()) continue;
      if (read == h.points) {
        Fail(number, fmt::format("more data lines than POINTS {}", h.points), kFixHeader);
      }
      if (tokens.size() != h.point_values) {
        Fail(number,
             fmt::format("{} values on the line but FIELDS/COUNT give {} a point", tokens.size(),
                         h.point_values),
             kFixHeader);
      }
      std::uint32_t rgb = 0;
      if (h.rgb >= 0) {
        const double packed = value(h.rgb);
        if (h.fields[h.rgb].type.kind == ScalarKind::kFloat) {
          const float as_float = static_cast<float>(packed);
          std::memcpy(&rgb, &as_float, sizeof(rgb));
        } else {
          // Converting a double outside 32 bits to an integer is undefined behaviour.
          if (!(packed >= 0.0 && packed <= 4294967295.0)) {
            Fail(number,
                 fmt::format("{} '{}' is not a packed 0xRRGGBB colour", h.fields[h.rgb].name,
                             tokens[h.fields[h.rgb].value]),
                 "fix or re-save the file");
          }
          rgb = static_cast<std::uint32_t>(packed);
        }
      }
      Emit({value(h.x), value(h.y), value(h.z)}, rgb, read);
      ++read;
    }
    if (read != h.points) {
      Fail(h.points_line, fmt::format("POINTS is {} but the data holds {} points", h.points, read),
           kFixHeader);
    }
  }

  // Decodes point `index` whose field f starts at field_bytes(f).
  template <typename FieldBytes>
  void EmitBinary(long long index, FieldBytes&& field_bytes) {
    const PcdHeader& h = header_;
    const Eigen::Vector3d point(DecodeScalar(field_bytes(h.x), h.fields[h.x].type, false),
                                DecodeScalar(field_bytes(h.y), h.fields[h.y].type, false),
                                DecodeScalar(field_bytes(h.z), h.fields[h.z].type, false));
    Emit(point, h.rgb >= 0 ? DecodeBits32(field_bytes(h.rgb), false) : 0u, index);
  }

  void ReadBinary(std::istream& stream, std::uintmax_t data_bytes) {
    const PcdHeader& h = header_;
    const auto points = static_cast<std::uintmax_t>(h.points);
    if (points > data_bytes / h.point_size || points * h.point_size != data_bytes) {
      Fail(h.points_line,
           fmt::format("POINTS {} x {} bytes a point (SIZE x COUNT) = {} bytes, but the data "
                       "holds {} bytes",
                       h.points, h.point_size,
                       points <= data_bytes ? std::to_string(points * h.point_size) : "more",
                       data_bytes),
           kFixHeader);
    }
    sink_.Reserve(static_cast<std::size_t>(points));
    constexpr std::size_t kChunk = 1 << 16;  // points read at a time
    // Never larger than the data: one point of a wide record (COUNT up to 10^6) times kChunk
    // would be gigabytes.
    std::vector<unsigned char> buffer(std::min<std::uintmax_t>(kChunk, points) * h.point_size);
    for (std::uintmax_t first = 0; first < points; first += kChunk) {
      const std::size_t n =
          static_cast<std::size_t>(std::min<std::uintmax_t>(kChunk, points - first));
      stream.read(reinterpret_cast<char*>(buffer.data()),
                  static_cast<std::streamsize>(n * h.point_size));
      CheckInput(stream.good(), name_, 0, "read error in the point data",
                 "check the file is complete and readable");
      for (std::size_t i = 0; i < n; ++i) {
        const unsigned char* record = buffer.data() + i * h.point_size;
        EmitBinary(static_cast<long long>(first + i),
                   [&](int f) { return record + h.fields[f].offset; });
      }
    }
  }

  void ReadCompressed(std::istream& stream, std::uintmax_t data_bytes) {
    const PcdHeader& h = header_;
    unsigned char sizes[8];
    CheckInput(data_bytes >= 8 && stream.read(reinterpret_cast<char*>(sizes), 8).good(), name_,
               h.data_line, "the binary_compressed data is missing its two size words", kFixHeader);
    const std::uint32_t compressed = DecodeBits32(sizes, false);
    const std::uint32_t uncompressed = DecodeBits32(sizes + 4, false);
    const auto points = static_cast<std::uintmax_t>(h.points);
    const std::uintmax_t expected =
        points > (1ULL << 40) / h.point_size ? (1ULL << 40) : points * h.point_size;
    if (uncompressed != expected) {
      Fail(h.points_line,
           fmt::format("POINTS {} x {} bytes a point (SIZE x COUNT) = {} bytes, but the "
                       "compressed block decompresses to {} bytes",
                       h.points, h.point_size, expected, uncompressed),
           kFixHeader);
    }
    if (compressed > data_bytes - 8) {
      Fail(h.data_line,
           fmt::format("the compressed block is {} bytes but the file holds {} after the header",
                       compressed, data_bytes - 8),
           kFixHeader);
    }
    // LZF turns at most 3 input bytes (a long back reference) into 264 output bytes; a header
    // claiming more is corrupt, and checking before allocating keeps a forged size word from
    // costing gigabytes.
    if (uncompressed / 88 > compressed) {
      Fail(h.data_line,
           fmt::format("the compressed block of {} bytes cannot decompress to {} bytes (LZF "
                       "expands at most 88 times)",
                       compressed, uncompressed),
           kFixHeader);
    }
    std::vector<std::uint8_t> packed(compressed);
    stream.read(reinterpret_cast<char*>(packed.data()), compressed);
    CheckInput(stream.good(), name_, 0, "read error in the point data",
               "check the file is complete and readable");
    std::vector<std::uint8_t> fields(uncompressed);
    CheckInput(LzfDecompress(packed.data(), packed.size(), fields.data(), fields.size()), name_,
               h.data_line, "the LZF-compressed point data is corrupt", kFixHeader);
    std::vector<std::uint8_t>().swap(packed);
    sink_.Reserve(static_cast<std::size_t>(points));
    // PCL stores the fields one after another: all x, then all y, ... (field f starts at
    // points * offset of f in a record).
    for (std::uintmax_t i = 0; i < points; ++i) {
      EmitBinary(static_cast<long long>(i), [&](int f) {
        const PcdField& field = h.fields[f];
        return fields.data() + points * field.offset +
               i * static_cast<std::size_t>(field.type.size) * field.count;
      });
    }
  }

  std::filesystem::path path_;
  std::string name_;
  VoxelAccumulator& sink_;
  std::vector<std::string>* comments_;
  PcdHeader header_;
  bool organized_ = false;
  std::size_t dropped_ = 0;
};

}  // namespace

std::size_t ReadPcd(const std::filesystem::path& path, VoxelAccumulator& sink,
                    std::vector<std::string>* comments) {
  return PcdReader(path, sink, comments).Read();
}

}  // namespace planeloc
