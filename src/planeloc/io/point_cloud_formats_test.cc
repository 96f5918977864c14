// Every .pcd / .ply variant mapping tools write, generated in a temp dir (by hand from the specs,
// point_cloud_fixtures_for_test.h, or with Open3D's writers), read back and checked for point
// count and coordinates; and one header/data disagreement per class, which must be an InputError
// naming the file and what disagrees.
#include <gtest/gtest.h>
#include <open3d/geometry/PointCloud.h>
#include <open3d/io/PointCloudIO.h>

#include <fstream>
#include <limits>

#include "planeloc/io/lzf.h"
#include "planeloc/io/point_cloud.h"
#include "planeloc/io/point_cloud_fixtures_for_test.h"
#include "planeloc/io/voxel_filter.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

using testing::FixturePoints;
using testing::PcdFile;
using testing::PcdFixture;
using testing::PlyFile;
using testing::PlyFixture;

void WriteBytes(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// float32 files hold the coordinates rounded to float; float64 and ascii ("%.17g") exactly.
void ExpectPoints(const PointCloud& cloud, const std::vector<Eigen::Vector3d>& expected,
                  bool float32, const std::string& what) {
  ASSERT_EQ(cloud.size(), expected.size()) << what;
  for (std::size_t i = 0; i < expected.size(); ++i) {
    for (int k = 0; k < 3; ++k) {
      const double want =
          float32 ? static_cast<double>(static_cast<float>(expected[i][k])) : expected[i][k];
      EXPECT_EQ(cloud.points[i][k], want) << what << ": point " << i << " axis " << k;
    }
  }
}

TEST(PointCloudFormatsTest, ReadsEveryPcdVariant) {
  TempDir dir;
  for (const char* data : {"ascii", "binary", "binary_compressed"}) {
    for (const bool float64 : {false, true}) {
      for (const bool extras : {false, true}) {
        PcdFixture fixture;
        fixture.data = data;
        fixture.float64 = float64;
        fixture.extras = extras;
        const std::string what = std::string(data) + (float64 ? " F8" : " F4") +
                                 (extras ? " with extra fields" : " x y z");
        const auto path = dir.path() / "cloud.pcd";
        WriteBytes(path, PcdFile(fixture));
        const PointCloud cloud = ReadPointCloud(path);
        ExpectPoints(cloud, FixturePoints(), !float64 && std::string(data) != "ascii", what);
        EXPECT_EQ(cloud.dropped_invalid, 0u) << what;
        EXPECT_EQ(cloud.source_points, FixturePoints().size()) << what;
        // rgb 0x00ff80ii (extras): red 1, green 128/255, blue i/255.
        ASSERT_EQ(cloud.has_colors(), extras) << what;
        if (extras) {
          EXPECT_DOUBLE_EQ(cloud.colors[3].x(), 1.0) << what;
          EXPECT_DOUBLE_EQ(cloud.colors[3].y(), 128.0 / 255.0) << what;
          EXPECT_DOUBLE_EQ(cloud.colors[3].z(), 3.0 / 255.0) << what;
        }
      }
    }
  }
}

TEST(PointCloudFormatsTest, OrganizedPcdDropsAndCountsNanPoints) {
  TempDir dir;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const char* data : {"ascii", "binary", "binary_compressed"}) {
    PcdFixture fixture;
    fixture.data = data;
    fixture.float64 = true;
    fixture.width = 3;
    fixture.height = 2;
    fixture.points[1] = {nan, nan, nan};
    fixture.points[4] = {nan, 1.0, nan};
    WriteBytes(dir.path() / "organized.pcd", PcdFile(fixture));
    const PointCloud cloud = ReadPointCloud(dir.path() / "organized.pcd");
    const std::vector<Eigen::Vector3d> all = FixturePoints();
    ExpectPoints(cloud, {all[0], all[2], all[3], all[5]}, false, data);
    EXPECT_EQ(cloud.dropped_invalid, 2u) << data;
    // The same NaN in an unorganized cloud is an error naming the point.
    fixture.width = 6;
    fixture.height = 1;
    WriteBytes(dir.path() / "flat.pcd", PcdFile(fixture));
    try {
      ReadPointCloud(dir.path() / "flat.pcd");
      FAIL() << "expected InputError";
    } catch (const InputError& e) {
      EXPECT_NE(e.problem().find("point 1 "), std::string::npos) << e.problem();
    }
  }
}

TEST(PointCloudFormatsTest, ReadsEveryPlyVariant) {
  TempDir dir;
  for (const char* format : {"ascii", "binary_little_endian", "binary_big_endian"}) {
    for (const bool float64 : {false, true}) {
      for (const bool extras : {false, true}) {
        PlyFixture fixture;
        fixture.format = format;
        fixture.float64 = float64;
        fixture.extras = extras;
        const std::string what = std::string(format) + (float64 ? " double" : " float") +
                                 (extras ? " with extra properties and a face" : " x y z");
        const auto path = dir.path() / "cloud.ply";
        WriteBytes(path, PlyFile(fixture));
        const PointCloud cloud = ReadPointCloud(path);
        ExpectPoints(cloud, FixturePoints(), !float64 && std::string(format) != "ascii", what);
        ASSERT_EQ(cloud.has_colors(), extras) << what;
        if (extras) {
          EXPECT_DOUBLE_EQ(cloud.colors[2].x(), 1.0) << what;
          EXPECT_DOUBLE_EQ(cloud.colors[2].y(), 2.0 / 255.0) << what;
        }
      }
    }
  }
}

TEST(PointCloudFormatsTest, ReadsWhatOpen3dWrites) {
  TempDir dir;
  open3d::geometry::PointCloud o3d;
  o3d.points_ = FixturePoints();
  o3d.normals_.assign(o3d.points_.size(), Eigen::Vector3d::UnitZ());
  using Option = open3d::io::WritePointCloudOption;
  struct Variant {
    const char* name;
    Option::IsAscii ascii;
    Option::Compressed compressed;
  };
  for (const Variant& v :
       {Variant{"ascii.pcd", Option::IsAscii::Ascii, Option::Compressed::Uncompressed},
        Variant{"binary.pcd", Option::IsAscii::Binary, Option::Compressed::Uncompressed},
        Variant{"compressed.pcd", Option::IsAscii::Binary, Option::Compressed::Compressed},
        Variant{"ascii.ply", Option::IsAscii::Ascii, Option::Compressed::Uncompressed},
        Variant{"binary.ply", Option::IsAscii::Binary, Option::Compressed::Uncompressed}}) {
    Option option;
    option.write_ascii = v.ascii;
    option.compressed = v.compressed;
    const auto path = dir.path() / v.name;
    ASSERT_TRUE(open3d::io::WritePointCloud(path.string(), o3d, option)) << v.name;
    const PointCloud cloud = ReadPointCloud(path);
    ASSERT_EQ(cloud.size(), o3d.points_.size()) << v.name;
    // Open3D writes float32 binary; ascii .pcd to float precision, ascii .ply with 6
    // significant digits (100.123456789012 -> 100.123: 4.6e-4 off).
    const double tolerance = std::string(v.name) == "ascii.ply" ? 1e-3 : 2e-5;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      EXPECT_LT((cloud.points[i] - o3d.points_[i]).norm(), tolerance) << v.name << " point " << i;
    }
  }
}

TEST(PointCloudFormatsTest, VoxelFilterWhileReading) {
  TempDir dir;
  PcdFixture fixture;
  fixture.float64 = true;
  fixture.points = {{0.1, 0.1, 0.1}, {0.3, 0.5, 0.9}, {5.2, 0.0, 0.0}, {-0.2, 0.0, 0.0}};
  fixture.width = 4;
  WriteBytes(dir.path() / "v.pcd", PcdFile(fixture));
  PointCloudReadOptions options;
  options.voxel_size = 1.0;
  const PointCloud cloud = ReadPointCloud(dir.path() / "v.pcd", options);
  // Voxels (-1,0,0), (0,0,0) with two points, (5,0,0); Z-order from the lowest voxel (-1,0,0):
  // x offsets 0, 1, 6.
  ASSERT_EQ(cloud.size(), 3u);
  EXPECT_EQ(cloud.source_points, 4u);
  EXPECT_TRUE(cloud.points[0].isApprox(Eigen::Vector3d(-0.2, 0.0, 0.0)));
  EXPECT_TRUE(cloud.points[1].isApprox(Eigen::Vector3d(0.2, 0.3, 0.5)));
  EXPECT_TRUE(cloud.points[2].isApprox(Eigen::Vector3d(5.2, 0.0, 0.0)));
  // Filtering again with the same voxels changes nothing.
  const PointCloud again = VoxelFilter(cloud, 1.0);
  ASSERT_EQ(again.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(again.points[i], cloud.points[i]);
  EXPECT_THROW(VoxelAccumulator(-1.0), OptionsError);
}

TEST(PointCloudFormatsTest, LzfBackReferences) {
  // "abcabcabcX": 3 literals, a back reference of length 6 at distance 3, 1 literal.
  const std::uint8_t in[] = {2, 'a', 'b', 'c', (6 - 2) << 5, 3 - 1, 0, 'X'};
  std::uint8_t out[10];
  ASSERT_TRUE(LzfDecompress(in, sizeof(in), out, sizeof(out)));
  EXPECT_EQ(std::string(reinterpret_cast<char*>(out), sizeof(out)), "abcabcabcX");
  // A reference before the start, and a stream shorter than promised.
  const std::uint8_t bad[] = {0, 'a', (3 - 2) << 5, 5};
  EXPECT_FALSE(LzfDecompress(bad, sizeof(bad), out, 4));
  EXPECT_FALSE(LzfDecompress(in, sizeof(in), out, 9));
  EXPECT_FALSE(LzfDecompress(in, 4, out, sizeof(out)));
}

// The problem text of the InputError reading `bytes` as `name` throws; fails when none is thrown
// or when it does not name the file.
std::string ReadError(const TempDir& dir, const std::string& name, const std::string& bytes) {
  const auto path = dir.path() / name;
  WriteBytes(path, bytes);
  try {
    ReadPointCloud(path);
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), path.string());
    return e.problem();
  }
  ADD_FAILURE() << name << ": no InputError";
  return "";
}

std::string Replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST(PointCloudFormatsTest, PcdHeaderDataMismatchesAreInputErrors) {
  TempDir dir;
  PcdFixture f;
  f.extras = false;
  const std::string binary = PcdFile(f);  // 6 points x 12 bytes
  auto expect = [&](const std::string& bytes, const std::string& needle) {
    const std::string problem = ReadError(dir, "bad.pcd", bytes);
    EXPECT_NE(problem.find(needle), std::string::npos) << "'" << problem << "' lacks " << needle;
  };
  // POINTS vs bytes: the header promises more points than the data holds, or fewer.
  expect(binary.substr(0, binary.size() - 12), "the data holds 60 bytes");
  expect(binary + std::string(12, '\0'), "the data holds 84 bytes");
  // Double coordinates declared as float (SIZE 4), the classic SIZE/TYPE mix-up.
  f.float64 = true;
  expect(Replace(PcdFile(f), "SIZE 8 8 8", "SIZE 4 4 4"), "the data holds 144 bytes");
  f.float64 = false;
  // WIDTH x HEIGHT vs POINTS.
  expect(Replace(binary, "HEIGHT 1", "HEIGHT 2"), "WIDTH x HEIGHT = 6 x 2 = 12 but POINTS is 6");
  // COUNT / SIZE / TYPE entries vs FIELDS, and an impossible SIZE for a TYPE.
  expect(Replace(binary, "COUNT 1 1 1", "COUNT 1 1"), "COUNT has 2 entries but FIELDS has 3");
  expect(Replace(binary, "SIZE 4 4 4", "SIZE 4 4 4 4"), "SIZE has 4 entries but FIELDS has 3");
  expect(Replace(binary, "TYPE F F F", "TYPE F F"), "TYPE has 2 entries but FIELDS has 3");
  expect(Replace(binary, "SIZE 4 4 4", "SIZE 4 4 2"), "TYPE F with SIZE 2");
  expect(Replace(binary, "TYPE F F F", "TYPE F F Q"), "TYPE 'Q'");
  expect(Replace(binary, "COUNT 1 1 1", "COUNT 1 1 2"), "COUNT 2 (coordinates need 1)");
  // ascii: fewer lines than POINTS, a line with a missing value, a value that is not a number.
  f.data = "ascii";
  const std::string ascii = PcdFile(f);
  expect(ascii.substr(0, ascii.rfind('\n', ascii.size() - 2) + 1),
         "POINTS is 6 but the data "
         "holds 5 points");
  expect(Replace(ascii, "\n0 0 -1.5\n", "\n0 0\n"), "2 values on the line");
  expect(Replace(ascii, "\n0 0 -1.5\n", "\n0 zero -1.5\n"), "y 'zero' is not a number");
  // binary_compressed: wrong uncompressed size, compressed block longer than the file, bad LZF.
  f.data = "binary_compressed";
  std::string compressed = PcdFile(f);
  const std::size_t sizes = compressed.find("DATA binary_compressed\n") + 23;
  std::string wrong_size = compressed;
  wrong_size[sizes + 4] = static_cast<char>(wrong_size[sizes + 4] + 4);  // 72 -> 76 bytes
  expect(wrong_size, "decompresses to 76 bytes");
  expect(compressed.substr(0, compressed.size() - 10), "after the header");
  std::string corrupt = compressed;
  corrupt[sizes + 8] = static_cast<char>(0xe0);  // a back reference before the start
  expect(corrupt, "corrupt");
  expect("hello\n", "not a .pcd file");
}

TEST(PointCloudFormatsTest, PlyHeaderDataMismatchesAreInputErrors) {
  TempDir dir;
  PlyFixture f;
  f.extras = false;
  const std::string binary = PlyFile(f);  // 6 vertices x 12 bytes
  auto expect = [&](const std::string& bytes, const std::string& needle) {
    const std::string problem = ReadError(dir, "bad.ply", bytes);
    EXPECT_NE(problem.find(needle), std::string::npos) << "'" << problem << "' lacks " << needle;
  };
  expect(Replace(binary, "element vertex 6", "element vertex 7"), "the file holds 72 bytes");
  expect(Replace(binary, "element vertex 6", "element vertex 5"), "the file holds 12");
  f.float64 = true;
  expect(Replace(PlyFile(f), "property double z", "property float z"), "the file holds 24");
  expect(Replace(binary, "property float z", "property real z"), "unknown property type");
  expect(Replace(binary, "property float z", "property float w"), "no x, y and z");
  f.float64 = false;
  f.format = "ascii";
  const std::string ascii = PlyFile(f);
  expect(Replace(ascii, "element vertex 6", "element vertex 7"),
         "element vertex 7 but the data holds 6 vertices");
  expect(Replace(ascii, "element vertex 6", "element vertex 5"), "the data 1");
  expect(Replace(ascii, "\n0 0 -1.5\n", "\n0 0\n"), "2 values on the line");
  expect(Replace(ascii, "format ascii", "format binary_middle_endian"), "unknown PLY format");
  expect("plyx\n", "not a .ply file");
}

}  // namespace
}  // namespace planeloc
