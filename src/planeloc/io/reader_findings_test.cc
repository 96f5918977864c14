// Regression tests for the defects the fuzz targets (*_fuzz.cc, scripts/fuzz.sh) and the sanitizer
// build found in the readers, each with the offending input inlined. Before the fix each one was
// a sanitizer report (undefined behaviour, a multi-gigabyte allocation) or a crash; now each is
// an InputError naming the file, or a correct read. docs/reliability.md lists them.
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "planeloc/io/point_cloud.h"
#include "planeloc/io/point_cloud_fixtures_for_test.h"
#include "planeloc/io/settings_reader.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

std::filesystem::path Write(const TempDir& dir, const std::string& name, const std::string& bytes) {
  const auto path = dir.path() / name;
  std::ofstream(path, std::ios::binary) << bytes;
  return path;
}

// The InputError's problem text, or "" (and a failure) when the read succeeds.
std::string CloudError(const std::filesystem::path& path, double voxel = 0.0) {
  try {
    ReadPointCloud(path, {.voxel_size = voxel});
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), path.string());
    return e.problem();
  }
  ADD_FAILURE() << path << ": no InputError";
  return "";
}

std::string PcdHeader(const std::string& fields, const std::string& size, const std::string& type,
                      const std::string& count, const std::string& width, const std::string& data,
                      const std::string& height = "1") {
  return "VERSION 0.7\nFIELDS " + fields + "\nSIZE " + size + "\nTYPE " + type + "\nCOUNT " +
         count + "\nWIDTH " + width + "\nHEIGHT " + height + "\nDATA " + data + "\n";
}

// OpenCV 4.6's YAML parser looped for ever (the settings fuzz target's 15 s timeout, 2026-12-05) on
// a document marker with text after it followed by more lines; the reader refuses the line first.
TEST(ReaderFindingsTest, SettingsDocumentMarkerWithTextDoesNotHang) {
  const TempDir dir;
  for (const std::string& text :
       {std::string("---C:0\n----\n1"), std::string("%YAML:1.0\nC: 0\n---C: 0\n----\n1\n")}) {
    const auto path = Write(dir, "settings.yaml", text);
    try {
      SettingsReader reader(path);
      ADD_FAILURE() << "no InputError for " << text;
    } catch (const InputError& e) {
      EXPECT_EQ(e.path(), path.string());
      EXPECT_GT(e.line(), 0);
      EXPECT_NE(e.problem().find("---"), std::string::npos);
    }
  }
  // A bare marker, with or without a comment, is still a settings file.
  const auto fine = Write(dir, "fine.yaml", "%YAML:1.0\n---  # start\nCamera.fps: 10\n");
  EXPECT_NO_THROW(SettingsReader reader(fine));
}

// WIDTH and HEIGHT each below the 2^40 limit, their product overflowing 64 bits (signed overflow).
TEST(ReaderFindingsTest, PcdWidthTimesHeightOverflow) {
  TempDir dir;
  const auto path = Write(
      dir, "wide.pcd",
      PcdHeader("x y z", "4 4 4", "F F F", "1 1 1", "1099511627776", "ascii", "1099511627776"));
  EXPECT_NE(CloudError(path).find("absurdly large"), std::string::npos);
}

// An integer rgb field outside 32 bits in an ascii .pcd: the double -> uint32 conversion was
// undefined behaviour.
TEST(ReaderFindingsTest, PcdAsciiRgbOutOfRange) {
  TempDir dir;
  for (const char* rgb : {"1e30", "-1", "nan"}) {
    const auto path = Write(dir, "rgb.pcd",
                            PcdHeader("x y z rgb", "4 4 4 4", "F F F U", "1 1 1 1", "1", "ascii") +
                                "1 2 3 " + rgb + "\n");
    EXPECT_NE(CloudError(path).find("is not a packed 0xRRGGBB colour"), std::string::npos) << rgb;
  }
}

// One binary point of 8 MB (a field with COUNT 10^6): the read buffer was 65536 records, 550 GB.
TEST(ReaderFindingsTest, PcdBinaryWideRecordReadsWithoutHugeBuffer) {
  TempDir dir;
  std::string bytes = PcdHeader("x y z pad", "4 4 4 8", "F F F F", "1 1 1 1000000", "1", "binary");
  testing::Put<float>(bytes, 1.0f);
  testing::Put<float>(bytes, 2.0f);
  testing::Put<float>(bytes, 3.0f);
  bytes.append(8'000'000, '\0');
  const PointCloud cloud = ReadPointCloud(Write(dir, "wide.pcd", bytes));
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_EQ(cloud.points[0], Eigen::Vector3d(1, 2, 3));
}

// A compressed block of 1 byte whose size word promises 1.2 GB: the reader allocated (and
// zeroed) the 1.2 GB before LZF said the block was corrupt.
TEST(ReaderFindingsTest, PcdCompressedSizeWordBeyondLzfRatio) {
  TempDir dir;
  std::string bytes =
      PcdHeader("x y z", "4 4 4", "F F F", "1 1 1", "100000000", "binary_compressed");
  testing::Put<std::uint32_t>(bytes, 1);            // compressed bytes
  testing::Put<std::uint32_t>(bytes, 1200000000u);  // uncompressed bytes = POINTS x 12
  bytes.push_back('\0');
  EXPECT_NE(CloudError(Write(dir, "forged.pcd", bytes)).find("cannot decompress to 1200000000"),
            std::string::npos);
}

// Two elements after the vertices of an ascii .ply, 2^62 lines each: their sum overflowed.
TEST(ReaderFindingsTest, PlyAsciiTrailingElementCountsOverflow) {
  TempDir dir;
  const auto path = Write(dir, "counts.ply",
                          "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty "
                          "float y\nproperty float z\nelement a 4611686018427387904\nproperty "
                          "int i\nelement b 4611686018427387904\nproperty int i\nend_header\n"
                          "1 2 3\n");
  EXPECT_NE(CloudError(path).find("elements after the vertices"), std::string::npos);
}

// A finite point 1e300 m away with a voxel filter: its voxel index (1e300 / 0.25) does not fit
// in 64 bits, and the conversion was undefined behaviour. With the index clamped to +-2^62, the
// Z-order sort's offset from the lowest voxel (2^62 - -2^62) overflowed next (found by this
// test in the sanitizer build).
TEST(ReaderFindingsTest, VoxelIndexOfAFarPoint) {
  TempDir dir;
  const PointCloud cloud =
      ReadPointCloud(Write(dir, "far.xyz", "1e300 0 0\n-1e308 5 5\n0 0 0\n"), {.voxel_size = 0.25});
  EXPECT_EQ(cloud.size(), 3u);
}

}  // namespace
}  // namespace planeloc
