#include "planeloc/io/map_updates.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <string>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

MapUpdates Example() {
  MapUpdates updates;
  updates.planes_path = "out/planes.json";
  updates.planes_hash = "0123456789abcdef";
  updates.planes_count = 3;
  updates.frame_name = "map";
  updates.sequence = "sim/sequences/00";
  updates.frames = 120;
  updates.trajectory = "out/traj.txt";
  PlaneUpdate unseen;
  unseen.id = 4;
  PlaneUpdate corrected;
  corrected.id = 9;
  corrected.status = PlaneUpdateStatus::kCorrected;
  corrected.points = 230;
  corrected.through = 2;
  corrected.frames = {10, 14, 19};
  corrected.disabled_at_frame = 19;
  corrected.offset = -0.1234;
  corrected.offset_sigma = 0.031;
  corrected.tilt = Eigen::Vector2d(0.001, -0.02);
  corrected.tilt_sigma = Eigen::Vector2d(1.0, 0.004);
  corrected.normal = Eigen::Vector3d(0.6, 0.8, 0);
  corrected.d = 3.5;
  PlaneUpdate contradicted;
  contradicted.id = 12;
  contradicted.status = PlaneUpdateStatus::kContradicted;
  contradicted.through = 77;
  contradicted.frames = {40};
  updates.planes = {unseen, corrected, contradicted};
  return updates;
}

void WriteText(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path) << text;
}

// The error's line when reading `text` as an updates file (0: no error).
int ErrorLine(const TempDir& dir, const std::string& text) {
  WriteText(dir.path() / "bad.json", text);
  try {
    ReadMapUpdates(dir.path() / "bad.json");
  } catch (const InputError& error) {
    return error.line();
  }
  return 0;
}

TEST(MapUpdatesTest, WrittenAndReadBack) {
  const TempDir dir;
  const MapUpdates written = Example();
  WriteMapUpdates(dir.path() / "u.json", written);
  const MapUpdates read = ReadMapUpdates(dir.path() / "u.json");
  EXPECT_EQ(read.planes_hash, written.planes_hash);
  EXPECT_EQ(read.planes_count, 3);
  EXPECT_EQ(read.frame_name, "map");
  EXPECT_EQ(read.frames, 120);
  ASSERT_EQ(read.planes.size(), 3u);
  EXPECT_EQ(read.planes[0].status, PlaneUpdateStatus::kUnseen);
  const PlaneUpdate& corrected = read.planes[1];
  EXPECT_EQ(corrected.status, PlaneUpdateStatus::kCorrected);
  EXPECT_EQ(corrected.frames, (std::vector<int>{10, 14, 19}));
  EXPECT_EQ(corrected.disabled_at_frame, 19);
  EXPECT_EQ(corrected.offset, -0.1234);  // doubles written with all their digits
  EXPECT_EQ(corrected.tilt_sigma, Eigen::Vector2d(1.0, 0.004));
  EXPECT_EQ(corrected.normal, Eigen::Vector3d(0.6, 0.8, 0));
  EXPECT_EQ(read.planes[2].status, PlaneUpdateStatus::kContradicted);
  EXPECT_EQ(read.planes[2].through, 77);
  EXPECT_FALSE(read.planes[2].disabled_at_frame.has_value());
}

TEST(MapUpdatesTest, BadEntriesNameTheirLine) {
  const TempDir dir;
  WriteMapUpdates(dir.path() / "u.json", Example());
  std::ifstream stream(dir.path() / "u.json");
  const std::string good((std::istreambuf_iterator<char>(stream)),
                         std::istreambuf_iterator<char>());
  const auto line_of = [&](const std::string& needle) {
    const std::size_t at = good.find(needle);
    return 1 + static_cast<int>(std::count(good.begin(), good.begin() + at, '\n'));
  };
  const auto replaced = [&](const std::string& from, const std::string& to) {
    std::string text = good;
    text.replace(text.find(from), from.size(), to);
    return text;
  };
  // A measured plane's sigma that is zero or negative; the error is at its entry's "id".
  EXPECT_EQ(ErrorLine(dir, replaced("\"offset_sigma\": 0.031", "\"offset_sigma\": 0.0")),
            line_of("\"id\": 9"));
  EXPECT_EQ(ErrorLine(dir, replaced("\"offset_sigma\": 0.031", "\"offset_sigma\": -1")),
            line_of("\"id\": 9"));
  EXPECT_EQ(ErrorLine(dir, replaced("\"contradicted\"", "\"gone\"")), line_of("\"id\": 12"));
  EXPECT_EQ(ErrorLine(dir, replaced("\"id\": 12", "\"id\": 9")), line_of("\"id\": 12"));
  EXPECT_GT(ErrorLine(dir, good.substr(0, good.size() / 2)), 0);  // truncated JSON
  EXPECT_THROW(ReadMapUpdates(dir.path() / "missing.json"), InputError);
  WriteText(dir.path() / "planes.json", "{\"planes\": []}\n");
  EXPECT_THROW(ReadMapUpdates(dir.path() / "planes.json"), InputError);  // no format
}

TEST(MapUpdatesTest, TheHashChangesWithAnyByte) {
  const TempDir dir;
  WriteText(dir.path() / "a.json", "{\"planes\": []}\n");
  WriteText(dir.path() / "b.json", "{\"planes\": [ ]}\n");
  const std::string a = FileHash(dir.path() / "a.json");
  EXPECT_EQ(a.size(), 16u);
  EXPECT_EQ(a, FileHash(dir.path() / "a.json"));
  EXPECT_NE(a, FileHash(dir.path() / "b.json"));
  // FNV-1a 64 of the empty input is its offset basis.
  WriteText(dir.path() / "empty", "");
  EXPECT_EQ(FileHash(dir.path() / "empty"), "cbf29ce484222325");
  EXPECT_THROW(FileHash(dir.path() / "missing"), InputError);
}

}  // namespace
}  // namespace planeloc
