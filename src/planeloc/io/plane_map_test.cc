#include "planeloc/io/plane_map.h"

#include <gtest/gtest.h>

#include <fstream>

#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc {
namespace {

namespace fs = std::filesystem;

void WriteText(const fs::path& path, const std::string& text) { std::ofstream(path) << text; }

PlaneMap ExampleMap() {
  PlaneMap map;
  MapPlane ground;
  ground.id = 3;
  ground.kind = "ground";
  ground.plane_in_map = Plane(Eigen::Vector3d(0.01, -1.0, 0.02), 1.73);
  ground.centroid = Eigen::Vector3d(0.1, 1.73, 12.5);
  ground.inliers = 52000;
  ground.rms = 0.021;
  ground.area = 640.25;
  ground.polygon = {{-5, 1.73, 0}, {5, 1.73, 0}, {5, 1.8, 60}, {-5, 1.8, 60}};
  MapPlane facade;
  facade.id = 7;
  facade.kind = "facade";
  facade.plane_in_map = Plane(Eigen::Vector3d(1, 0, 0.1), -6.0 / 3.0);
  ground.sigma.offset = 0.0123;
  ground.sigma.normal = Eigen::Vector2d(1.5e-4, 3.25e-3);
  ground.sigma.major_axis = ground.plane_in_map.normal.unitOrthogonal();
  facade.sigma.offset = 0.031;
  facade.sigma.normal = Eigen::Vector2d(2e-3, 7e-4);
  facade.sigma.major_axis = facade.plane_in_map.normal.cross(Eigen::Vector3d::UnitY()).normalized();
  map.planes = {ground, facade};
  map.stats = {{"planes", 2}, {"seconds", 1.25}};
  return map;
}

TEST(PlaneMap, RoundTripIsExact) {
  TempDir dir;
  const PlaneMap map = ExampleMap();
  WritePlaneMap(dir.path() / "planes.json", map);
  const PlaneMap copy = ReadPlaneMap(dir.path() / "planes.json");
  ASSERT_EQ(copy.planes.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    const MapPlane& a = map.planes[i];
    const MapPlane& b = copy.planes[i];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.kind, b.kind);
    EXPECT_EQ(a.plane_in_map.normal, b.plane_in_map.normal);  // bit-exact doubles
    EXPECT_EQ(a.plane_in_map.d, b.plane_in_map.d);
    EXPECT_EQ(a.centroid, b.centroid);
    EXPECT_EQ(a.inliers, b.inliers);
    EXPECT_EQ(a.rms, b.rms);
    EXPECT_EQ(a.area, b.area);
    EXPECT_EQ(a.polygon, b.polygon);
    EXPECT_EQ(a.sigma.offset, b.sigma.offset);
    EXPECT_EQ(a.sigma.normal, b.sigma.normal);
    EXPECT_EQ(a.sigma.major_axis, b.sigma.major_axis);
  }
  EXPECT_FALSE(copy.sigma_defaulted);
  EXPECT_EQ(copy.stats, map.stats);
  EXPECT_FALSE(copy.frame.known());  // none written
}

TEST(PlaneMap, FrameRoundTripsAndIsOptional) {
  TempDir dir;
  PlaneMap map = ExampleMap();
  map.frame.name = "lio_sam_map";
  map.frame.map_file = "/data/GlobalMap.pcd";
  map.frame.up = Eigen::Vector3d::UnitZ();
  map.frame.up_source = "detected";
  WritePlaneMap(dir.path() / "planes.json", map);
  const PlaneMap copy = ReadPlaneMap(dir.path() / "planes.json");
  ASSERT_TRUE(copy.frame.known());
  EXPECT_EQ(copy.frame.name, "lio_sam_map");
  EXPECT_EQ(copy.frame.map_file, "/data/GlobalMap.pcd");
  EXPECT_EQ(copy.frame.up, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(copy.frame.up_source, "detected");
  // An old file (no "frame") still reads, with the frame unknown.
  WriteText(dir.path() / "old.json", R"({"planes":[{"normal":[0,0,1],"d":-2.5}],"stats":{}})");
  EXPECT_FALSE(ReadPlaneMap(dir.path() / "old.json").frame.known());
}

TEST(PlaneMap, MissingOptionalFieldsDefault) {
  TempDir dir;
  WriteText(dir.path() / "planes_gt.json",
            R"({"planes":[{"normal":[0,0,1],"d":-2.5},{"id":9,"normal":[0,1,0],"d":1}]})");
  const PlaneMap map = ReadPlaneMap(dir.path() / "planes_gt.json");
  ASSERT_EQ(map.planes.size(), 2u);
  EXPECT_EQ(map.planes[0].id, 0);  // position in the array
  EXPECT_EQ(map.planes[1].id, 9);
  EXPECT_EQ(map.planes[0].kind, "");
  EXPECT_EQ(map.planes[0].inliers, 0);
  EXPECT_EQ(map.planes[0].rms, 0.0);
  EXPECT_EQ(map.planes[0].area, 0.0);
  EXPECT_EQ(map.planes[0].centroid, Eigen::Vector3d::Zero());
  EXPECT_TRUE(map.planes[0].polygon.empty());
  EXPECT_EQ(map.planes[0].plane_in_map.d, -2.5);
  EXPECT_TRUE(map.stats.is_object() && map.stats.empty());
}

TEST(PlaneMap, FileWithoutSigmaGetsTheDocumentedDefault) {
  TempDir dir;
  WriteText(dir.path() / "old.json",
            R"({"planes":[{"normal":[0,0,1],"d":-2.5},{"id":9,"normal":[0,0.6,0.8],"d":1}]})");
  const PlaneMap map = ReadPlaneMap(dir.path() / "old.json");
  EXPECT_TRUE(map.sigma_defaulted);
  for (const MapPlane& plane : map.planes) {
    EXPECT_EQ(plane.sigma.offset, 0.05);                             // docs/map.md
    EXPECT_EQ(plane.sigma.normal, Eigen::Vector2d(0.0035, 0.0035));  // 0.2 deg
    EXPECT_NEAR(plane.sigma.major_axis.norm(), 1.0, 1e-12);
    EXPECT_NEAR(plane.sigma.major_axis.dot(plane.plane_in_map.normal), 0.0, 1e-12);
  }
  WriteText(dir.path() / "empty.json", R"({"planes":[]})");
  EXPECT_FALSE(ReadPlaneMap(dir.path() / "empty.json").sigma_defaulted);
}

TEST(PlaneMap, NearlyUnitNormalIsNormalizedWithItsOffset) {
  TempDir dir;
  WriteText(dir.path() / "planes.json", R"({"planes":[{"normal":[0,0,1.0005],"d":2.001}]})");
  const Plane plane = ReadPlaneMap(dir.path() / "planes.json").planes[0].plane_in_map;
  EXPECT_NEAR(plane.normal.norm(), 1.0, 1e-15);
  EXPECT_NEAR(plane.d, 2.001 / 1.0005, 1e-12);  // the same plane z = -2.0
}

// Expects an InputError for `json_text` whose message contains `needle`; returns the error line.
int ExpectBad(const std::string& json_text, const std::string& needle) {
  TempDir dir;
  const fs::path path = dir.path() / "planes.json";
  WriteText(path, json_text);
  try {
    ReadPlaneMap(path);
    ADD_FAILURE() << "expected InputError for " << json_text;
  } catch (const InputError& error) {
    EXPECT_EQ(error.path(), path.string());
    EXPECT_NE(std::string(error.what()).find(needle), std::string::npos) << error.what();
    EXPECT_FALSE(error.fix().empty());
    return error.line();
  }
  return -1;
}

TEST(PlaneMapBadInput, EachMalformedDocumentIsNamed) {
  ExpectBad(R"({"planes":[{"normal":[0,0,1.1],"d":1}]})", "|normal| = 1.1");
  ExpectBad(R"({"planes":[{"normal":[0,0,0],"d":1}]})", "|normal| = 0");
  ExpectBad(R"({"planes":[{"normal":[0,0,1]}]})", "`normal` and `d` are required");
  ExpectBad(R"({"planes":[{"normal":[0,1],"d":1}]})", "array of 3 numbers");
  ExpectBad(R"({"planes":[{"normal":[0,0,"1"],"d":1}]})", "`normal` is not a number");
  ExpectBad(R"({"planes":[{"normal":[0,0,1],"d":1e999}]})", "invalid JSON");
  ExpectBad(R"({"planes":[{"normal":[0,0,1],"d":1},{"normal":[0,0,1],"d":"x"}]})", "plane 1");
  ExpectBad(R"({"planes":[{"id":1,"normal":[0,0,1],"d":1},{"id":1,"normal":[0,1,0],"d":1}]})",
            "repeats id 1");
  ExpectBad(R"({"planes":[{"normal":[0,0,1],"d":1,"inliers":-3}]})", "negative");
  ExpectBad(R"({"planes":[{"normal":[0,0,1],"d":1,"polygon":[[0,0]]}]})", "polygon vertex");
  ExpectBad(R"({"surfaces":[]})", "no `planes` array");
  ExpectBad(R"({"planes":[],"frame":{"name":"map","up":[0,0,2]}})", "frame: |up| = 2");
  ExpectBad(R"({"planes":[],"frame":{"name":3}})", "frame: `name` is not a string");
  ExpectBad(R"([1,2])", "no `planes` array");
  EXPECT_EQ(ExpectBad("{\n\"planes\": [\n{\"normal\": [0,0,1],, \"d\": 1}\n]}", "invalid JSON"), 3);
}

// A plane written one field per line, with `sigma_json` (empty: none) as its sigma.
std::string PlaneLines(int id, const std::string& sigma_json) {
  std::string text = "{\n\"id\": " + std::to_string(id) + ",\n\"normal\": [0, 0, 1],\n\"d\": 1";
  if (!sigma_json.empty()) text += ",\n\"sigma\": " + sigma_json;
  return text + "\n}";
}

TEST(PlaneMapBadInput, EachBadSigmaIsNamedWithItsPlaneAndLine) {
  const std::string good = R"({"offset": 0.02, "normal": [0.001, 0.002], "major_axis": [1, 0, 0]})";
  const auto file = [&](const std::string& second) {
    return "{\"planes\": [\n" + PlaneLines(4, good) + ",\n" + PlaneLines(5, second) + "\n]}";
  };
  // Line 1: "planes"; lines 2-7: the first plane; the second plane's "id" is on line 9 and its
  // "sigma" on line 12.
  EXPECT_EQ(ExpectBad(file(R"({"offset": 0, "normal": [0.001, 0.002], "major_axis": [1, 0, 0]})"),
                      "plane 1 (0-based): `sigma.offset` is 0, must be positive"),
            12);
  EXPECT_EQ(ExpectBad(file(R"({"offset": 0.1, "normal": [-0.001, 0.002], "major_axis": [1,0,0]})"),
                      "`sigma.normal` is -0.001"),
            12);
  // nlohmann::json writes a NaN as null.
  EXPECT_EQ(ExpectBad(file(R"({"offset": null, "normal": [0.001, 0.002], "major_axis": [1,0,0]})"),
                      "`sigma.offset` is not a number"),
            12);
  ExpectBad(file(R"({"offset": 0.1, "normal": [0.001], "major_axis": [1, 0, 0]})"),
            "array of 2 numbers");
  ExpectBad(file(R"({"offset": 0.1, "normal": [0.001, 0.002], "major_axis": [0, 0, 1]})"),
            "unit vector in the plane");
  ExpectBad(file(R"({"offset": 0.1, "normal": [0.001, 0.002], "major_axis": [2, 0, 0]})"),
            "unit vector in the plane");
  ExpectBad(file(R"({"offset": 0.1, "normal": [0.001, 0.002]})"), "`sigma` has no `major_axis`");
  // Present on one plane, missing on the other: the plane without one, at its "id" line.
  EXPECT_EQ(ExpectBad(file(""), "plane 1 (0-based, id 5) has no `sigma` while 1 of the 2"), 9);
}

TEST(PlaneMapBadInput, MissingFile) {
  TempDir dir;
  EXPECT_THROW(ReadPlaneMap(dir.path() / "planes.json"), InputError);
}

}  // namespace
}  // namespace planeloc
