#include "planeloc/sim/raycast.h"

#include <gtest/gtest.h>

#include <random>

#include "planeloc/sim/world.h"

namespace planeloc::sim {
namespace {

World GroundAndWall() {
  World world;
  Quad ground;
  ground.origin = Eigen::Vector3d(-500, -500, 0);
  ground.edge_u = Eigen::Vector3d(1000, 0, 0);
  ground.edge_v = Eigen::Vector3d(0, 1000, 0);
  ground.material = Material::kAsphalt;
  world.AddPlanarQuad(ground, "ground");
  Quad wall;  // x = 10, facing -x
  wall.origin = Eigen::Vector3d(10, 5, 0);
  wall.edge_u = Eigen::Vector3d(0, -10, 0);
  wall.edge_v = Eigen::Vector3d(0, 0, 8);
  world.AddPlanarQuad(wall, "facade");
  return world;
}

TEST(RaycastTest, HitsGroundAndWallAtTheRightDistance) {
  const World world = GroundAndWall();
  const Scene scene(world);
  Hit hit;
  ASSERT_TRUE(scene.Intersect({0, 0, 2}, Eigen::Vector3f(1, 0, 0), 1e4f, &hit));
  EXPECT_NEAR(hit.t, 10.0f, 1e-4f);
  EXPECT_EQ(hit.index, 1u);
  EXPECT_NEAR(hit.normal.x(), -1.0f, 1e-6f);
  EXPECT_NEAR(hit.uv.x(), 5.0f, 1e-4f);  // metres along edge_u from (10, 5)
  EXPECT_NEAR(hit.uv.y(), 2.0f, 1e-4f);  // height
  const Eigen::Vector3f down = Eigen::Vector3f(1, 0, -1).normalized();
  ASSERT_TRUE(scene.Intersect({0, 0, 2}, down, 1e4f, &hit));
  EXPECT_NEAR(hit.t, 2.0f * std::sqrt(2.0f), 1e-4f);
  EXPECT_EQ(hit.index, 0u);
  EXPECT_FALSE(scene.Intersect({0, 0, 2}, Eigen::Vector3f(0, 0, 1), 1e4f, &hit));  // sky
  EXPECT_FALSE(scene.Intersect({0, 0, 2}, Eigen::Vector3f(1, 0, 0), 9.0f, &hit));  // t_max
  EXPECT_TRUE(scene.Occluded({0, 0, 2}, Eigen::Vector3f(1, 0, 0), 100.0f));
  EXPECT_FALSE(scene.Occluded({0, 0, 2}, Eigen::Vector3f(-1, 0, 0), 100.0f));
}

// The tree must return exactly what testing every primitive would.
TEST(RaycastTest, BvhAgreesWithBruteForce) {
  World world = GroundAndWall();
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-40, 40), r(0.3, 2.0);
  for (int i = 0; i < 300; ++i) {
    Sphere s;
    s.center = Eigen::Vector3d(u(rng), u(rng), r(rng) + 1.0);
    s.radius = r(rng);
    world.spheres.push_back(s);
    Cylinder c;
    c.base = Eigen::Vector3d(u(rng), u(rng), 0);
    c.radius = 0.2;
    c.height = 4.0;
    world.cylinders.push_back(c);
    world.AddClutterBox(Eigen::Vector3d(u(rng), u(rng), 0), u(rng), 4.0, 2.0, 1.5,
                        Material::kCarPaint, i);
  }
  const Scene scene(world);
  std::uniform_real_distribution<float> angle(-3.14159f, 3.14159f), pitch(-0.4f, 0.3f);
  int hits = 0;
  for (int k = 0; k < 6000; ++k) {
    const float a = angle(rng), p = pitch(rng);
    const Eigen::Vector3f dir(std::cos(p) * std::cos(a), std::cos(p) * std::sin(a), std::sin(p));
    const Eigen::Vector3f origin(u(rng) * 0.5f, u(rng) * 0.5f, 1.7f);
    Hit tree, linear;
    const bool found = scene.Intersect(origin, dir, 1e4f, &tree);
    ASSERT_EQ(found, scene.IntersectLinear(origin, dir, 1e4f, &linear)) << "ray " << k;
    ASSERT_EQ(found, scene.Occluded(origin, dir, 1e4f)) << "ray " << k;
    if (!found) continue;
    ++hits;
    EXPECT_EQ(tree.t, linear.t) << "ray " << k;
    // Index may differ on exact ties (coplanar box tops); the distance may not.
    const Eigen::Vector3d point = (origin + tree.t * dir).cast<double>();
    EXPECT_LT(world.DistanceToSurface(point), 1e-3) << "ray " << k;
    if (k % 100 != 0) continue;
  }
  EXPECT_GT(hits, 3000);
}

}  // namespace
}  // namespace planeloc::sim
