#include "planeloc/io/point_cloud.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <limits>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

PointCloud ThreePoints() {
  PointCloud cloud;
  cloud.points = {{1.0, 2.0, 3.0}, {-4.5, 0.25, 7.0}, {0.0, 0.0, -1.5}};
  return cloud;
}

void ExpectSamePoints(const PointCloud& a, const PointCloud& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_LT((a.points[i] - b.points[i]).norm(), 1e-5) << i;
  }
}

TEST(PointCloudTest, RoundTripsEveryFormat) {
  TempDir dir;
  for (const char* name : {"c.pcd", "c.ply", "c.xyz"}) {
    const auto path = dir.path() / name;
    WritePointCloud(path, ThreePoints());
    ExpectSamePoints(ReadPointCloud(path), ThreePoints());
  }
}

// A map carries how it was made in its header (map build's counts, issue 37): comments survive
// a write and a read in both formats that have a header, and a line break cannot end one early.
TEST(PointCloudTest, HeaderCommentsRoundTrip) {
  TempDir dir;
  PointCloud cloud = ThreePoints();
  cloud.comments = {"planeloc map build {\"scans\":8,\"empty_scans\":1}", "two\nlines"};
  for (const char* name : {"c.pcd", "c.ply"}) {
    const auto path = dir.path() / name;
    WritePointCloud(path, cloud);
    const PointCloud read = ReadPointCloud(path);
    ExpectSamePoints(read, cloud);
    const std::vector<std::string>& comments = read.comments;
    // The .ply writer's own "planeloc" comment comes first.
    const auto first = std::find(comments.begin(), comments.end(), cloud.comments[0]);
    ASSERT_NE(first, comments.end()) << name;
    ASSERT_NE(first + 1, comments.end()) << name;
    EXPECT_EQ(first[1], "two lines") << name;
  }
  // A PCD written by PCL: "#" comments anywhere in the header, with or without a space.
  const auto pcl = dir.path() / "pcl.pcd";
  std::ofstream(pcl) << "# .PCD v0.7 - Point Cloud Data file format\n#made by a scanner\n"
                        "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                        "WIDTH 1\nHEIGHT 1\n# site 4\nPOINTS 1\nDATA ascii\n1 2 3\n";
  EXPECT_EQ(ReadPointCloud(pcl).comments,
            (std::vector<std::string>{"made by a scanner", "site 4"}));
}

TEST(PointCloudTest, KeepsColors) {
  TempDir dir;
  PointCloud cloud = ThreePoints();
  cloud.colors = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  WritePointCloud(dir.path() / "c.ply", cloud);
  const PointCloud read = ReadPointCloud(dir.path() / "c.ply");
  ASSERT_TRUE(read.has_colors());
  EXPECT_NEAR(read.colors[1].y(), 1.0, 1e-2);
  EXPECT_NEAR(read.colors[1].x(), 0.0, 1e-2);
}

void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// SIZE 4, TYPE F, COUNT 1 for each of the (space-separated) fields.
std::string AsciiPcd(const std::string& fields, const std::string& data, int n) {
  const std::string count = std::to_string(n);
  std::string sizes, types, counts;
  for (std::size_t k = 0;
       k <= static_cast<std::size_t>(std::count(fields.begin(), fields.end(), ' ')); ++k) {
    sizes += " 4";
    types += " F";
    counts += " 1";
  }
  return "# .PCD v0.7\nVERSION 0.7\nFIELDS " + fields + "\nSIZE" + sizes + "\nTYPE" + types +
         "\nCOUNT" + counts + "\n" + "WIDTH " + count +
         "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + count + "\nDATA ascii\n" + data;
}

TEST(PointCloudTest, ReadsAsciiPcd) {
  TempDir dir;
  WriteText(dir.path() / "a.pcd", AsciiPcd("x y z", "1 2 3\n4 5 6\n", 2));
  const PointCloud cloud = ReadPointCloud(dir.path() / "a.pcd");
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_DOUBLE_EQ(cloud.points[1].z(), 6.0);
}

TEST(PointCloudTest, IgnoresUnknownPcdFieldsButNeedsXyz) {
  TempDir dir;
  WriteText(dir.path() / "label.pcd", AsciiPcd("x y z label", "1 2 3 7\n", 1));
  EXPECT_EQ(ReadPointCloud(dir.path() / "label.pcd").size(), 1u);
  // As FAST-LIO and PCL's ascii writer give them (rgb: the packed colour printed as a float).
  WriteText(dir.path() / "fastlio.pcd",
            AsciiPcd("x y z intensity normal_x normal_y normal_z curvature",
                     "1 2 3 17 0 0 1 0.01\n-4 5.5 6 3 1 0 0 0.2\n", 2));
  const PointCloud fastlio = ReadPointCloud(dir.path() / "fastlio.pcd");
  ASSERT_EQ(fastlio.size(), 2u);
  EXPECT_EQ(fastlio.points[1], Eigen::Vector3d(-4, 5.5, 6));
  WriteText(dir.path() / "rgb.pcd", AsciiPcd("x y z rgb", "1 2 3 4.2108e+06\n", 1));
  const PointCloud rgb = ReadPointCloud(dir.path() / "rgb.pcd");
  ASSERT_EQ(rgb.size(), 1u);
  EXPECT_EQ(rgb.points[0], Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(rgb.has_colors());
  const auto path = dir.path() / "u.pcd";
  WriteText(path, AsciiPcd("u v w", "1 2 3\n", 1));
  try {
    ReadPointCloud(path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.path(), path.string());
    EXPECT_EQ(e.line(), 3);
    EXPECT_NE(e.problem().find("x, y and z"), std::string::npos) << e.problem();
  }
}

TEST(PointCloudTest, RejectsNanAndInfNamingThePoint) {
  TempDir dir;
  for (double bad :
       {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    PointCloud cloud = ThreePoints();
    cloud.points[2].y() = bad;
    const auto path = dir.path() / "bad.ply";
    WritePointCloud(path, cloud);
    try {
      ReadPointCloud(path);
      FAIL() << "expected InputError";
    } catch (const InputError& e) {
      EXPECT_EQ(e.path(), path.string());
      EXPECT_NE(e.problem().find("point 2"), std::string::npos) << e.problem();
    }
  }
}

TEST(PointCloudTest, RejectsEmptyMissingAndUnknownExtension) {
  TempDir dir;
  WriteText(dir.path() / "empty.pcd", AsciiPcd("x y z", "", 0));
  try {
    ReadPointCloud(dir.path() / "empty.pcd");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(e.problem().find("empty"), std::string::npos) << e.problem();
  }
  WriteText(dir.path() / "empty.xyz", "");
  EXPECT_THROW(ReadPointCloud(dir.path() / "empty.xyz"), InputError);
  EXPECT_THROW(ReadPointCloud(dir.path() / "missing.pcd"), InputError);
  EXPECT_THROW(ReadPointCloud(dir.path() / "cloud.las"), InputError);
  EXPECT_THROW(WritePointCloud(dir.path() / "cloud.las", ThreePoints()), InputError);
}

TEST(PointCloudTest, XyzLinesNeedTheSameColumnsAndNumbers) {
  TempDir dir;
  const auto path = dir.path() / "c.xyz";
  // (text, line of the defect)
  for (const auto& [text, line] : std::vector<std::pair<std::string, int>>{
           {"1 2 3\n4 5\n", 2},         // short line (Open3D dropped it silently)
           {"1 2 3 9\n4 5 6\n", 2},     // columns change
           {"# c\n1 2 3\n4 x 6\n", 3},  // not a number
           {"1 2\n", 1}}) {             // no z
    WriteText(path, text);
    try {
      ReadPointCloud(path);
      ADD_FAILURE() << "expected InputError for " << text;
    } catch (const InputError& e) {
      EXPECT_EQ(e.path(), path.string());
      EXPECT_EQ(e.line(), line) << text;
    }
  }
  WriteText(path, "# x y z intensity\n1 2 3 0.5\n\n4 5 6 0.7\n");
  EXPECT_EQ(ReadPointCloud(path).size(), 2u);
}

TEST(PointCloudTest, WriteToAFullDiskIsAnError) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  TempDir dir;
  for (const char* name : {"full.pcd", "full.ply", "full.xyz"}) {
    // A symlink keeps the extension that chooses the format; the device is written in place.
    std::filesystem::create_symlink("/dev/full", dir.path() / name);
    try {
      WritePointCloud(dir.path() / name, ThreePoints());
      ADD_FAILURE() << "no error writing " << name;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("No space left on device"), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace planeloc
