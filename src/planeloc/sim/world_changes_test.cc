#include "planeloc/sim/world_changes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iostream>
#include <iterator>
#include <memory>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/sim/raycast.h"
#include "planeloc/sim/render.h"
#include "planeloc/sim/shading.h"
#include "planeloc/sim/simulator.h"
#include "planeloc/sim/texture.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc::sim {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;
using Eigen::Vector3f;

SimOptions Tiny(int frames, const std::string& changes) {
  SimOptions options = SimOptions::FromPreset("tiny");
  options.frames = frames;
  options.show_progress = false;
  options.changes = ParseWorldChanges(changes);
  return options;
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

const Quad* QuadOfPlane(const World& world, int plane_id) {
  for (const Quad& quad : world.quads) {
    if (quad.plane_id == plane_id) return &quad;
  }
  return nullptr;
}

std::vector<int> PlanesLabelled(const Scenario& scenario, PlaneChange change) {
  std::vector<int> ids;
  for (std::size_t id = 0; id < scenario.plane_changes.size(); ++id) {
    if (scenario.plane_changes[id].change == change) ids.push_back(static_cast<int>(id));
  }
  return ids;
}

// A ray 1 m in front of the facade `quad`, towards it, that hits `quad` itself in `scene` (not a
// tree crown in between); false when every point of a 5 x 5 grid on the facade is hidden.
bool UnobstructedRayTo(const Scene& scene, const Quad& quad, int plane_id, Vector3f* origin,
                       Vector3f* dir) {
  const Vector3d normal = quad.Normal();
  for (const double u : {0.5, 0.3, 0.7, 0.15, 0.85}) {
    for (const double v : {0.5, 0.3, 0.7, 0.15, 0.85}) {
      const Vector3d on_wall = quad.origin + u * quad.edge_u + v * quad.edge_v;
      *origin = (on_wall + normal).cast<float>();
      *dir = (-normal).cast<float>();
      Hit hit;
      if (scene.Intersect(*origin, *dir, 100.0f, &hit) && hit.kind == PrimitiveKind::kQuad &&
          scene.world().quads[hit.index].plane_id == plane_id) {
        return true;
      }
    }
  }
  return false;
}

// The tiny preset's scenario with the `renovation` changes (no rendering, ~0.1 s), and one ray
// scene per world: the cameras' (now) and the LiDAR's (at mapping time).
class WorldChangesTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    scenario_ = std::make_unique<Scenario>(BuildScenario(Tiny(60, "renovation")));
    now_ = std::make_unique<Scene>(scenario_->world);
    then_ = std::make_unique<Scene>(scenario_->LidarWorld());
  }
  static void TearDownTestSuite() {
    now_.reset();
    then_.reset();
    scenario_.reset();
  }
  static std::unique_ptr<Scenario> scenario_;
  static std::unique_ptr<Scene> now_;   // cameras
  static std::unique_ptr<Scene> then_;  // LiDAR
};
std::unique_ptr<Scenario> WorldChangesTest::scenario_;
std::unique_ptr<Scene> WorldChangesTest::now_;
std::unique_ptr<Scene> WorldChangesTest::then_;

TEST(WorldChangesSpecTest, ParsesPresetsAndItemsIntoOneCanonicalSpec) {
  EXPECT_EQ(ParseWorldChanges("renovation").ToSpec(),
            "moved=0.3,offset=0.1:0.5,removed=1,new=1,cars=6");
  EXPECT_FALSE(ParseWorldChanges("none").Any());
  EXPECT_EQ(ParseWorldChanges("none").ToSpec(), "none");
  const WorldChangesOptions items = ParseWorldChanges("cars=4,moved=0.25,offset=0.2:0.3,new=2");
  EXPECT_DOUBLE_EQ(items.moved_fraction, 0.25);
  EXPECT_DOUBLE_EQ(items.min_offset, 0.2);
  EXPECT_DOUBLE_EQ(items.max_offset, 0.3);
  EXPECT_EQ(items.removed_buildings, 0);
  EXPECT_EQ(items.new_walls, 2);
  EXPECT_EQ(items.parked_cars, 4);
  EXPECT_EQ(items.ToSpec(), "moved=0.25,offset=0.2:0.3,new=2,cars=4");
  EXPECT_EQ(ParseWorldChanges(items.ToSpec()).ToSpec(), items.ToSpec());
  EXPECT_EQ(ParseWorldChanges("removed=0").ToSpec(), "none");
}

TEST(WorldChangesSpecTest, RejectsMalformedSpecsNamingTheFlagAndTheForm) {
  for (const std::string spec : {"",
                                 "bogus",
                                 "moved",
                                 "moved=",
                                 "moved=1.5",
                                 "moved=abc",
                                 "moved=nan",
                                 "offset=0.5:0.1",
                                 "offset=0:0.3",
                                 "offset=0.1",
                                 "offset=0.1:3",
                                 "offset=0.1:0.2:0.3",
                                 "removed=-1",
                                 "cars=2.5",
                                 "cars=101",
                                 "new=1,new=2",
                                 "moved=0.3,",
                                 ",cars=1",
                                 "renovation,cars=1",
                                 "Cars=1"}) {
    try {
      ParseWorldChanges(spec);
      ADD_FAILURE() << "accepted '" << spec << "'";
    } catch (const InputError& error) {
      const std::string message = error.what();
      EXPECT_NE(message.find("--changes"), std::string::npos) << message;
      EXPECT_NE(message.find("KEY=VALUE"), std::string::npos) << message;
    }
  }
  WorldChangesOptions out_of_range;
  out_of_range.moved_fraction = 0.2;
  out_of_range.max_offset = 5.0;
  EXPECT_THROW(out_of_range.Check(), InputError);
}

// Each label is checked against the two worlds' geometry, not against the drawing code.
TEST_F(WorldChangesTest, LabelsMatchTheGeometryOfBothWorlds) {
  const World& then = scenario_->LidarWorld();
  const World& now = scenario_->world;
  ASSERT_EQ(scenario_->plane_changes.size(), now.planes.size());
  int counts[4] = {0, 0, 0, 0};
  for (std::size_t i = 0; i < now.planes.size(); ++i) {
    const int id = static_cast<int>(i);
    const PlaneChangeLabel& label = scenario_->plane_changes[i];
    ++counts[static_cast<int>(label.change)];
    const Quad* before = QuadOfPlane(then, id);
    const Quad* after = QuadOfPlane(now, id);
    SCOPED_TRACE("plane " + std::to_string(id) + " " + PlaneChangeName(label.change));
    switch (label.change) {
      case PlaneChange::kUnchanged:
        ASSERT_TRUE(before && after);
        EXPECT_EQ(now.planes[i].plane.normal, then.planes[i].plane.normal);
        EXPECT_EQ(now.planes[i].plane.d, then.planes[i].plane.d);
        EXPECT_NEAR(before->Normal().dot(after->origin - before->origin), 0.0, 1e-9);
        break;
      case PlaneChange::kMoved:
        ASSERT_TRUE(before && after);
        EXPECT_EQ(before->material, Material::kFacade);
        EXPECT_NEAR((after->Normal() - before->Normal()).norm(), 0.0, 1e-9);
        EXPECT_NEAR(before->Normal().dot(after->origin - before->origin), label.offset_m, 1e-9);
        EXPECT_NEAR(now.planes[i].plane.d, then.planes[i].plane.d - label.offset_m, 1e-9);
        EXPECT_GE(std::abs(label.offset_m), 0.1 - 1e-12);
        EXPECT_LE(std::abs(label.offset_m), 0.5 + 1e-12);
        break;
      case PlaneChange::kRemoved:
        EXPECT_TRUE(before != nullptr);
        EXPECT_TRUE(after == nullptr);
        break;
      case PlaneChange::kNew:
        EXPECT_GE(i, then.planes.size());
        EXPECT_TRUE(before == nullptr);
        ASSERT_TRUE(after != nullptr);
        EXPECT_EQ(after->material, Material::kFacade);
        break;
    }
  }
  // Measured on tiny seeds 1..5: 4, 5, 6, 5, 6 facades moved (0.3 of the ground-level facades
  // near the drive), one free-standing building (3 facades) removed, one new wall, six cars.
  const ChangeCounts& done = scenario_->change_counts;
  EXPECT_GE(done.moved_facades, 2);
  EXPECT_EQ(counts[static_cast<int>(PlaneChange::kMoved)], done.moved_facades);
  EXPECT_EQ(done.removed_buildings, 1);
  EXPECT_EQ(counts[static_cast<int>(PlaneChange::kRemoved)], 3 * done.removed_buildings);
  EXPECT_EQ(done.new_walls, 1);
  EXPECT_EQ(counts[static_cast<int>(PlaneChange::kNew)], done.new_walls);
  EXPECT_EQ(done.parked_cars, 6);
  EXPECT_EQ(then.planes.size() + static_cast<std::size_t>(done.new_walls), now.planes.size());
}

TEST_F(WorldChangesTest, CameraRaysSeeAMovedFacadeAtItsNewOffsetLidarRaysAtTheOld) {
  int checked = 0;
  for (const int id : PlanesLabelled(*scenario_, PlaneChange::kMoved)) {
    const double offset = scenario_->plane_changes[static_cast<std::size_t>(id)].offset_m;
    Vector3f origin, dir;
    if (!UnobstructedRayTo(*then_, *QuadOfPlane(scenario_->LidarWorld(), id), id, &origin, &dir))
      continue;
    Hit then_hit, now_hit;
    ASSERT_TRUE(then_->Intersect(origin, dir, 100.0f, &then_hit));
    ASSERT_TRUE(now_->Intersect(origin, dir, 100.0f, &now_hit));
    EXPECT_NEAR(then_hit.t, 1.0, 1e-4) << "plane " << id;
    // The ray runs against the normal: a facade moved by +offset (towards the street) is hit
    // `offset` metres earlier.
    EXPECT_EQ(scenario_->world.quads[now_hit.index].plane_id, id);
    EXPECT_NEAR(now_hit.t, 1.0 - offset, 1e-4) << "plane " << id;
    ++checked;
  }
  EXPECT_GE(checked, 2);
}

// The strip between a moved facade's old and new vertical edge is covered now (by a stretched
// side wall or a step where a neighbour's wall met it): no building is left open to look into.
TEST_F(WorldChangesTest, MovedFacadesLeaveNoOpenCorner) {
  int corners = 0;
  for (const int id : PlanesLabelled(*scenario_, PlaneChange::kMoved)) {
    const Quad& before = *QuadOfPlane(scenario_->LidarWorld(), id);
    const double offset = scenario_->plane_changes[static_cast<std::size_t>(id)].offset_m;
    for (const Vector3d& corner : {before.origin, Vector3d(before.origin + before.edge_u)}) {
      for (const double height : {0.5, 0.5 * before.edge_v.z(), before.edge_v.z() - 0.5}) {
        const Vector3d middle =
            corner + 0.5 * offset * before.Normal() + height * Vector3d::UnitZ();
        EXPECT_LT(scenario_->world.DistanceToSurface(middle), 1e-6)
            << "plane " << id << " open at height " << height;
      }
      ++corners;
    }
  }
  EXPECT_EQ(corners, 2 * scenario_->change_counts.moved_facades);
}

TEST_F(WorldChangesTest, RemovedBuildingIsInTheLidarWorldOnlyNewWallInTheCamerasOnly) {
  int removed = 0, added = 0;
  for (const int id : PlanesLabelled(*scenario_, PlaneChange::kRemoved)) {
    Vector3f origin, dir;
    if (!UnobstructedRayTo(*then_, *QuadOfPlane(scenario_->LidarWorld(), id), id, &origin, &dir))
      continue;
    Hit hit;
    const bool any = now_->Intersect(origin, dir, 100.0f, &hit);
    EXPECT_TRUE(!any || hit.t > 1.5f) << "plane " << id << ": something where the wall was";
    ++removed;
  }
  for (const int id : PlanesLabelled(*scenario_, PlaneChange::kNew)) {
    Vector3f origin, dir;
    ASSERT_TRUE(UnobstructedRayTo(*now_, *QuadOfPlane(scenario_->world, id), id, &origin, &dir));
    Hit hit;
    const bool any = then_->Intersect(origin, dir, 100.0f, &hit);
    EXPECT_TRUE(!any || hit.t > 1.5f) << "plane " << id << ": a wall there at mapping time";
    ++added;
  }
  EXPECT_GE(removed, 1);
  EXPECT_EQ(added, scenario_->change_counts.new_walls);
}

// A horizontal ray from the lane at door height towards each mapping-only car: the LiDAR's world
// has the car body there, the cameras' world has nothing within 2.5 m (the car has left).
TEST_F(WorldChangesTest, MappingOnlyCarsAreInTheLidarWorldOnly) {
  const auto roofs = [](const World& world) {
    std::vector<const Quad*> out;
    for (const Quad& q : world.quads) {
      if (q.material == Material::kCarPaint && q.Normal().z() > 0.9) out.push_back(&q);
    }
    return out;
  };
  const std::vector<const Quad*> then_roofs = roofs(scenario_->LidarWorld());
  const std::vector<const Quad*> now_roofs = roofs(scenario_->world);
  ASSERT_EQ(then_roofs.size(),
            now_roofs.size() + static_cast<std::size_t>(scenario_->change_counts.parked_cars));
  int checked = 0;
  for (const Quad* roof : then_roofs) {
    const Vector3d centre = roof->origin + 0.5 * roof->edge_u + 0.5 * roof->edge_v;
    bool parked_now = false;
    for (const Quad* other : now_roofs) {
      parked_now =
          parked_now ||
          (other->origin + 0.5 * other->edge_u + 0.5 * other->edge_v - centre).norm() < 0.1;
    }
    if (parked_now) continue;
    Vector3d nearest = scenario_->world_from_cam.front().translation;
    for (const auto& pose : scenario_->world_from_cam) {
      if ((pose.translation - centre).head<2>().norm() < (nearest - centre).head<2>().norm())
        nearest = pose.translation;
    }
    const Vector3d forward = roof->edge_u.normalized();
    Vector3d lateral = nearest - centre;
    lateral.z() = 0.0;
    lateral = (lateral - lateral.dot(forward) * forward).normalized();
    const Vector3f origin =
        Vector3d(centre.x(), centre.y(), 0.6).cast<float>() + (2.0 * lateral).cast<float>();
    const Vector3f dir = (-lateral).cast<float>();
    Hit hit;
    ASSERT_TRUE(then_->Intersect(origin, dir, 2.5f, &hit));
    EXPECT_EQ(scenario_->LidarWorld().quads[hit.index].material, Material::kCarPaint);
    EXPECT_NEAR(hit.t, 2.0 - 0.5 * 1.75, 0.1);  // the body is 1.75 m wide
    EXPECT_FALSE(now_->Intersect(origin, dir, 2.5f, &hit));
    ++checked;
  }
  EXPECT_EQ(checked, scenario_->change_counts.parked_cars);
}

TEST(WorldChangesDrawTest, DrawsDependOnSeedAndSpecOnlyNotOnFrames) {
  const Scenario a = BuildScenario(Tiny(60, "renovation"));
  const Scenario b = BuildScenario(Tiny(60, "renovation"));
  const Scenario short_run = BuildScenario(Tiny(5, "renovation"));
  SimOptions other_seed = Tiny(60, "renovation");
  other_seed.seed = 2;
  const Scenario c = BuildScenario(other_seed);
  const auto same = [](const Scenario& x, const Scenario& y) {
    if (x.plane_changes.size() != y.plane_changes.size()) return false;
    for (std::size_t i = 0; i < x.plane_changes.size(); ++i) {
      if (x.plane_changes[i].change != y.plane_changes[i].change ||
          x.plane_changes[i].offset_m != y.plane_changes[i].offset_m)
        return false;
    }
    return x.world.quads.size() == y.world.quads.size() &&
           x.LidarWorld().quads.size() == y.LidarWorld().quads.size();
  };
  EXPECT_TRUE(same(a, b));
  EXPECT_TRUE(same(a, short_run)) << "--frames must not change the drawn changes of a preset";
  EXPECT_FALSE(same(a, c));
  // Kinds draw from separate streams: the moved facades do not depend on the car count.
  SimOptions fewer_cars = Tiny(60, "moved=0.3,offset=0.1:0.5,removed=1,new=1,cars=1");
  const Scenario d = BuildScenario(fewer_cars);
  EXPECT_EQ(PlanesLabelled(a, PlaneChange::kMoved), PlanesLabelled(d, PlaneChange::kMoved));
}

TEST(WorldChangesDrawTest, NoChangesIsTheSameWorldForBothSensors) {
  const Scenario plain = BuildScenario(Tiny(5, "none"));
  EXPECT_FALSE(plain.mapping_world.has_value());
  EXPECT_TRUE(plain.plane_changes.empty());
  EXPECT_EQ(&plain.LidarWorld(), &plain.world);
  // ApplyWorldChanges with nothing to do returns the town unchanged in both worlds.
  const StreetPath street = StreetPath::FromCorners({{0.0, 0.0}, {200.0, 0.0}}, false, 0.0);
  const World town = BuildTown(street, 7u);
  const ChangedWorld changed =
      ApplyWorldChanges(town, street, {Vector3d(50.0, -1.75, 1.65)}, WorldChangesOptions{}, 7u);
  for (const World* world : {&changed.at_mapping, &changed.now}) {
    ASSERT_EQ(world->quads.size(), town.quads.size());
    for (std::size_t i = 0; i < town.quads.size(); ++i) {
      EXPECT_EQ(world->quads[i].origin, town.quads[i].origin);
      EXPECT_EQ(world->quads[i].edge_u, town.quads[i].edge_u);
    }
  }
  for (const PlaneChangeLabel& label : changed.labels) {
    EXPECT_EQ(label.change, PlaneChange::kUnchanged);
  }
}

// The written sequence: images are the cameras' world rendered, scans the LiDAR's world scanned,
// planes_gt.json the mapping-time planes with labels (ReadPlaneMap still loads it), and the same
// arguments write the same bytes. One frame (~1 s to render).
TEST(WorldChangesSequenceTest, ImagesRenderNowScansSeeMappingTimeFilesAreDeterministic) {
  const SimOptions options = Tiny(1, "renovation");
  TempDir dir("planeloc-sim-changes"), again("planeloc-sim-changes-again");
  const SimResult result = GenerateSequence(options, dir.path());
  GenerateSequence(options, again.path());
  for (const fs::path& relative :
       {fs::path("sequences/00/image_0/000000.png"), fs::path("sequences/00/image_1/000000.png"),
        fs::path("sequences/00/velodyne/000000.bin"), fs::path("poses/00.txt"),
        fs::path("world/planes_gt.json"), fs::path("world/README.txt")}) {
    EXPECT_EQ(ReadBytes(dir.path() / relative), ReadBytes(again.path() / relative)) << relative;
  }

  const Scenario scenario = BuildScenario(options);
  ASSERT_TRUE(scenario.mapping_world.has_value());
  const TextureBank bank = TextureBank::Procedural(HashCombine(options.seed, 3u));
  const Scene now(scenario.world), then(*scenario.mapping_world);
  const Shader now_shader(scenario.world, bank), then_shader(*scenario.mapping_world, bank);
  const Rigid3d& world_from_cam = scenario.world_from_cam.front();
  const FrameLighting light = LightingForFrame(options.lighting, options.seed, 0);
  const std::uint32_t left_seed = HashCombine(options.seed, 0u, 0u);
  const cv::Mat written =
      cv::imread((result.sequence_dir / "image_0" / "000000.png").string(), cv::IMREAD_UNCHANGED);
  const cv::Mat rendered_now =
      RenderView(now, now_shader, result.camera, world_from_cam, light, left_seed);
  const cv::Mat rendered_then =
      RenderView(then, then_shader, result.camera, world_from_cam, light, left_seed);
  EXPECT_EQ(cv::countNonZero(written != rendered_now), 0) << "the cameras must see the world now";
  EXPECT_GT(cv::countNonZero(written != rendered_then), 1000) << "no change in view of frame 0";

  const Rigid3d world_from_velo = world_from_cam * result.cam_from_velo;
  const std::uint32_t scan_seed = HashCombine(options.seed, 0u, 2u);
  const VelodyneScan scan = ReadVelodyneScan(result.sequence_dir / "velodyne" / "000000.bin");
  const VelodyneScan scanned_then = ScanLidar(then, then_shader, world_from_velo, scan_seed);
  const VelodyneScan scanned_now = ScanLidar(now, now_shader, world_from_velo, scan_seed);
  ASSERT_EQ(scan.points.size(), scanned_then.points.size()) << "the LiDAR must see mapping time";
  for (std::size_t i = 0; i < scan.points.size(); i += 97) {
    EXPECT_NEAR((scan.points[i] - scanned_then.points[i]).norm(), 0.0, 1e-5);
  }
  bool same_as_now = scan.points.size() == scanned_now.points.size();
  for (std::size_t i = 0; same_as_now && i < scan.points.size(); ++i) {
    same_as_now = (scan.points[i] - scanned_now.points[i]).norm() < 1e-5;
  }
  EXPECT_FALSE(same_as_now) << "no change in view of the LiDAR at frame 0";

  // The LiDAR's returns on a moved facade lie on its mapping-time plane, not at the new offset.
  int on_moved = 0, at_old_plane = 0;
  for (std::size_t id = 0; id < scenario.plane_changes.size(); ++id) {
    if (scenario.plane_changes[id].change != PlaneChange::kMoved) continue;
    const Quad& before = *QuadOfPlane(*scenario.mapping_world, static_cast<int>(id));
    const Plane& plane = scenario.mapping_world->planes[id].plane;
    for (const Vector3d& point_in_velo : scan.points) {
      const Vector3d p = world_from_velo * point_in_velo;
      const double along = plane.SignedDistance(p);
      // Points in front of the wall's interior (0.3 m away from its edges, where side walls and
      // neighbours meet it), up to 0.6 m off the plane.
      const Vector3d on_plane = p - along * plane.normal;
      if (std::abs(along) > 0.6 || DistanceToQuad(before, on_plane) > 1e-6) continue;
      const Vector3d rel = on_plane - before.origin;
      const double a = rel.dot(before.edge_u) / before.edge_u.squaredNorm();
      const double b = rel.dot(before.edge_v) / before.edge_v.squaredNorm();
      if (a * before.edge_u.norm() < 0.3 || (1 - a) * before.edge_u.norm() < 0.3 ||
          b * before.edge_v.norm() < 0.3 || (1 - b) * before.edge_v.norm() < 0.3)
        continue;
      ++on_moved;
      at_old_plane += std::abs(along) < 0.06;  // 3 sigma of the 2 cm range noise
    }
  }
  std::cout << "LiDAR returns on moved facades at frame 0: " << on_moved << ", within 6 cm of the "
            << "mapping-time plane: " << at_old_plane << "\n";
  EXPECT_GT(on_moved, 100);
  EXPECT_GE(at_old_plane, 0.97 * on_moved);

  // The planes file: mapping-time planes, labelled, still a valid plane map without the new wall.
  const PlaneMap map = ReadPlaneMap(result.planes_path);
  EXPECT_EQ(map.planes.size(), scenario.mapping_world->planes.size());
  std::ifstream in(result.planes_path);
  const nlohmann::json document = nlohmann::json::parse(in);
  int moved = 0;
  for (const auto& plane : document["planes"]) {
    const std::size_t id = plane["id"].get<std::size_t>();
    const PlaneChangeLabel& label = scenario.plane_changes[id];
    EXPECT_EQ(plane["change"], PlaneChangeName(label.change));
    if (label.change == PlaneChange::kMoved) {
      EXPECT_DOUBLE_EQ(plane["offset_m"].get<double>(), label.offset_m);
      ++moved;
    }
  }
  EXPECT_EQ(moved, scenario.change_counts.moved_facades);
  ASSERT_EQ(document["new_planes"].size(), 1u);
  EXPECT_EQ(document["new_planes"][0]["change"], "new");
  EXPECT_EQ(document["stats"]["changes"]["spec"], options.changes.ToSpec());
  EXPECT_NE(
      ReadBytes(dir.path() / "world" / "README.txt").find("changes: " + options.changes.ToSpec()),
      std::string::npos);
}

}  // namespace
}  // namespace planeloc::sim
