#include "planeloc/map/map_update.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

MapPlane Wall(int id, double x) {
  MapPlane plane;
  plane.id = id;
  plane.plane_in_map = Plane(Eigen::Vector3d(1, 0, 0), -x);
  plane.centroid = Eigen::Vector3d(x, -2, 20);
  plane.polygon = {{x, -6, 0}, {x, 1.65, 0}, {x, 1.65, 40}, {x, -6, 40}};
  plane.area = 300;
  plane.sigma.offset = 0.05;
  plane.sigma.normal = Eigen::Vector2d(0.0035, 0.0035);
  plane.sigma.major_axis = Eigen::Vector3d(0, 0, 1);
  return plane;
}

PlaneMap Map() {
  PlaneMap map;
  map.planes = {Wall(1, 6), Wall(2, -6), Wall(3, 20), Wall(4, 30)};
  map.frame.name = "map";
  map.source = "planes.json";
  return map;
}

PlaneUpdate Measured(int id, PlaneUpdateStatus status, double offset, double sigma) {
  PlaneUpdate update;
  update.id = id;
  update.status = status;
  update.points = 100;
  update.frames = {5, 9};
  update.offset = offset;
  update.offset_sigma = sigma;
  update.tilt_sigma = Eigen::Vector2d(1.0, 1.0);  // not constrained
  update.normal = Eigen::Vector3d(1, 0, 0);
  return update;
}

MapUpdates RunUpdates(const std::string& name, std::vector<PlaneUpdate> planes) {
  MapUpdates updates;
  updates.source = name;
  updates.sequence = "drive " + name;
  updates.planes_hash = "00000000000000aa";
  updates.planes_count = 4;
  updates.frame_name = "map";
  updates.planes = std::move(planes);
  return updates;
}

PlaneUpdate Contradicted(int id) {
  PlaneUpdate update;
  update.id = id;
  update.status = PlaneUpdateStatus::kContradicted;
  update.through = 60;
  update.frames = {30};
  return update;
}

TEST(MapUpdateTest, RunsMoveConfirmRetireAndLeaveUnseenPlanes) {
  const PlaneMap map = Map();
  // Plane 1 moved back by 0.2 m in both runs; plane 2 where it is; plane 3 torn down (seen
  // through in both runs); plane 4 never seen.
  const std::vector<MapUpdates> runs = {
      RunUpdates("a.json",
                 {Measured(1, PlaneUpdateStatus::kCorrected, 0.19, 0.03),
                  Measured(2, PlaneUpdateStatus::kConfirmed, 0.01, 0.03), Contradicted(3)}),
      RunUpdates("b.json",
                 {Measured(1, PlaneUpdateStatus::kCorrected, 0.21, 0.03),
                  Measured(2, PlaneUpdateStatus::kConfirmed, -0.01, 0.03), Contradicted(3)})};
  const MapUpdateResult result = FuseMapUpdates(map, runs);
  ASSERT_EQ(result.changes.size(), 4u);
  EXPECT_EQ(result.changes[0].action, PlaneChangeAction::kMoved);
  EXPECT_EQ(result.changes[1].action, PlaneChangeAction::kConfirmed);
  EXPECT_EQ(result.changes[2].action, PlaneChangeAction::kRetired);
  EXPECT_EQ(result.changes[3].action, PlaneChangeAction::kUnchanged);
  ASSERT_EQ(result.planes.planes.size(), 3u);  // plane 3 left the map
  // Moved: to the runs' mean, x = 6.2, with their fused sigma 0.03 / sqrt(2); the map's 5 cm
  // is no prior for a plane that moved.
  const MapPlane& moved = result.planes.planes[0];
  EXPECT_NEAR(moved.plane_in_map.d, -6.2, 1e-9);
  EXPECT_NEAR(moved.centroid.x(), 6.2, 1e-9);
  for (const Eigen::Vector3d& vertex : moved.polygon) EXPECT_NEAR(vertex.x(), 6.2, 1e-9);
  EXPECT_NEAR(moved.sigma.offset, 0.03 / std::sqrt(2.0), 1e-9);
  EXPECT_EQ(moved.sigma.normal, map.planes[0].sigma.normal);  // no run measured its tilt
  EXPECT_EQ(moved.provenance.size(), 2u);
  EXPECT_EQ(moved.provenance[0]["status"], "corrected");
  // Confirmed: kept as it is, its sigma too.
  const MapPlane& confirmed = result.planes.planes[1];
  EXPECT_EQ(confirmed.sigma.offset, 0.05);
  EXPECT_EQ(confirmed.plane_in_map.d, 6.0);
  EXPECT_EQ(result.planes.planes[2].id, 4);
  EXPECT_TRUE(result.planes.planes[2].provenance.empty());
  EXPECT_EQ(result.planes.stats["map_update"]["retired"], nlohmann::json::array({3}));
  EXPECT_EQ(result.planes.stats["map_update"]["counts"]["moved"], 1);
  const std::string report = ChangesMarkdown(map, runs, result);
  EXPECT_NE(report.find("| 1 | moved | 2 / 0 / 2 | +0.200 |"), std::string::npos) << report;
  EXPECT_NE(report.find("| 3 | retired | 0 / 2 / 2 |"), std::string::npos) << report;
}

TEST(MapUpdateTest, ARunThatDisagreesWithinTheMapsSigmaOnlyConfirms) {
  // 6 cm off with 3 cm sigma against the map's 5 cm: chi2 = 0.06^2 / (0.05^2 + 0.03^2) = 1.1.
  const MapUpdateResult result = FuseMapUpdates(
      Map(), {RunUpdates("a.json", {Measured(1, PlaneUpdateStatus::kCorrected, 0.06, 0.03)})});
  EXPECT_EQ(result.changes[0].action, PlaneChangeAction::kConfirmed);
  EXPECT_NEAR(result.changes[0].chi2, 0.0036 / 0.0034, 1e-9);
  EXPECT_EQ(result.planes.planes[0].plane_in_map.d, -6.0);
}

TEST(MapUpdateTest, OneRunOffTheMapMakesItSuspectNotMoved) {
  // One run's measurements share its trajectory's error: 0.2 m off is not enough to move it.
  const PlaneMap map = Map();
  const MapUpdateResult result = FuseMapUpdates(
      map, {RunUpdates("a.json", {Measured(1, PlaneUpdateStatus::kCorrected, 0.2, 0.03)})});
  EXPECT_EQ(result.changes[0].action, PlaneChangeAction::kSuspect);
  EXPECT_NEAR(result.changes[0].offset, 0.2, 1e-9);
  EXPECT_NEAR(result.changes[0].offset_sigma, 0.03, 1e-9);
  EXPECT_EQ(result.planes.planes[0].plane_in_map.d, -6.0);
  EXPECT_EQ(result.planes.planes[0].provenance.size(), 1u);
}

TEST(MapUpdateTest, TwoRunsOfTheSameDriveCountOnce) {
  MapUpdates a = RunUpdates("a.json", {Measured(1, PlaneUpdateStatus::kCorrected, 0.2, 0.03)});
  MapUpdates b = RunUpdates("b.json", {Measured(1, PlaneUpdateStatus::kCorrected, 0.2, 0.03)});
  b.sequence = a.sequence;
  EXPECT_EQ(FuseMapUpdates(Map(), {a, b}).changes[0].action, PlaneChangeAction::kSuspect);
}

TEST(MapUpdateTest, RunsThatDisagreeDoNotMoveAPlane) {
  // Both runs put it off the map, by 0.45 and 0.05 m: their mean (0.25 m) is neither.
  const MapUpdateResult result = FuseMapUpdates(
      Map(), {RunUpdates("a.json", {Measured(1, PlaneUpdateStatus::kCorrected, 0.45, 0.03)}),
              RunUpdates("b.json", {Measured(1, PlaneUpdateStatus::kConfirmed, 0.05, 0.03)})});
  EXPECT_EQ(result.changes[0].action, PlaneChangeAction::kSuspect);
  EXPECT_NE(result.changes[0].reason.find("disagree"), std::string::npos);
  EXPECT_EQ(result.planes.planes[0].plane_in_map.d, -6.0);
}

TEST(MapUpdateTest, AMeasuredTiltRotatesThePlaneAboutItsCentroid) {
  PlaneUpdate update = Measured(1, PlaneUpdateStatus::kCorrected, 0.0, 0.01);
  // 2 deg about n x major = (1,0,0) x (0,0,1) = (0,-1,0): the normal turns towards +z.
  update.tilt = Eigen::Vector2d(0.0, 2.0 * kDeg);
  update.tilt_sigma = Eigen::Vector2d(1.0, 0.002);
  const MapUpdateResult result =
      FuseMapUpdates(Map(), {RunUpdates("a.json", {update}), RunUpdates("b.json", {update})});
  ASSERT_EQ(result.changes[0].action, PlaneChangeAction::kMoved);
  const Plane& plane = result.planes.planes[0].plane_in_map;
  EXPECT_NEAR(plane.normal.dot(Eigen::Vector3d(0, 0, 1)), std::sin(2.0 * kDeg), 1e-4);
  EXPECT_NEAR(plane.SignedDistance(Eigen::Vector3d(6, -2, 20)), 0.0, 1e-9);  // the centroid
  EXPECT_NEAR(result.planes.planes[0].sigma.normal.y(), 0.002 / std::sqrt(2.0), 1e-9);
}

TEST(MapUpdateTest, UpdatesFromAnotherMapAreRefusedNamingBothFiles) {
  const PlaneMap map = Map();
  const MapUpdates run = RunUpdates("runs/a.json", {});
  EXPECT_NO_THROW(CheckUpdatesMatch(map, "00000000000000aa", run));
  const auto message = [&](const std::string& hash, const MapUpdates& updates) -> std::string {
    try {
      CheckUpdatesMatch(map, hash, updates);
    } catch (const InputError& error) {
      return error.path() + ": " + error.problem();
    }
    return "";
  };
  const std::string wrong_hash = message("00000000000000bb", run);
  EXPECT_NE(wrong_hash.find("runs/a.json"), std::string::npos) << wrong_hash;
  EXPECT_NE(wrong_hash.find("planes.json"), std::string::npos) << wrong_hash;
  MapUpdates unknown_id = run;
  unknown_id.planes = {Contradicted(17)};
  EXPECT_NE(message("00000000000000aa", unknown_id).find("plane id 17"), std::string::npos);
  MapUpdates other_frame = run;
  other_frame.frame_name = "utm";
  EXPECT_NE(message("00000000000000aa", other_frame).find("utm"), std::string::npos);
  MapUpdates other_count = run;
  other_count.planes_count = 5;
  EXPECT_NE(message("00000000000000aa", other_count).find("5 planes"), std::string::npos);
}

}  // namespace
}  // namespace planeloc
