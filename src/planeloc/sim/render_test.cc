#include "planeloc/sim/render.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "planeloc/sim/street.h"
#include "planeloc/sim/texture.h"

namespace planeloc::sim {
namespace {

// Ground, a plain wall 20 m ahead (x = 20, facing -x) and a 1 m marker (black 0.5 m square on
// white) on it, centred at `marker_centre`.
World MarkerWorld(const Eigen::Vector3d& marker_centre) {
  World world;
  Quad ground;
  ground.origin = Eigen::Vector3d(-200, -200, 0);
  ground.edge_u = Eigen::Vector3d(400, 0, 0);
  ground.edge_v = Eigen::Vector3d(0, 400, 0);
  ground.material = Material::kAsphalt;
  world.AddPlanarQuad(ground, "ground");
  Quad wall;
  wall.origin = Eigen::Vector3d(20, 15, 0);
  wall.edge_u = Eigen::Vector3d(0, -30, 0);
  wall.edge_v = Eigen::Vector3d(0, 0, 10);
  wall.material = Material::kCurb;
  world.AddPlanarQuad(wall, "facade");
  Quad marker = wall;
  marker.origin = marker_centre + Eigen::Vector3d(-0.01, 0.5, -0.5);
  marker.edge_u = Eigen::Vector3d(0, -1, 0);
  marker.edge_v = Eigen::Vector3d(0, 0, 1);
  marker.material = Material::kMarker;
  world.AddClutterQuad(marker);
  return world;
}

// Centroid of the dark square within `radius` of `guess`, pixels weighted by their coverage
// (linear between the window's white and black levels).
Eigen::Vector2d DarkCentroid(const cv::Mat& image, const Eigen::Vector2d& guess, int radius) {
  const cv::Rect window(static_cast<int>(std::lround(guess.x())) - radius,
                        static_cast<int>(std::lround(guess.y())) - radius, 2 * radius + 1,
                        2 * radius + 1);
  double black = 0.0, white = 0.0;
  cv::minMaxLoc(image(window), &black, &white);
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double weight = 0.0;
  for (int y = window.y; y < window.y + window.height; ++y) {
    for (int x = window.x; x < window.x + window.width; ++x) {
      const double w = (white - image.at<std::uint8_t>(y, x)) / (white - black);
      sum += w * Eigen::Vector2d(x, y);
      weight += w;
    }
  }
  return sum / weight;
}

// A GT 3-D point on a facade appears where the camera model projects it, in both images.
TEST(RenderTest, MarkerAppearsAtItsProjection) {
  const Eigen::Vector3d marker(20.0, 2.3, 2.7);
  const World world = MarkerWorld(marker);
  const Scene scene(world);
  const TextureBank bank = TextureBank::Procedural(1);
  const Shader shader(world, bank);
  const StereoCamera camera = Kitti07Camera();
  // A camera 1.65 m up, yawed 4 degrees left and pitched slightly: not an axis-aligned pose.
  const Eigen::Matrix3d world_from_vehicle = (Eigen::AngleAxisd(0.07, Eigen::Vector3d::UnitZ()) *
                                              Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitY()))
                                                 .toRotationMatrix();
  const Rigid3d world_from_cam(Eigen::Matrix3d(world_from_vehicle * VehicleFromCamRotation()),
                               Eigen::Vector3d(0.3, -0.2, 1.65));
  const Rigid3d left_from_right(Eigen::Quaterniond::Identity(),
                                Eigen::Vector3d(camera.baseline, 0, 0));
  CameraRenderOptions options;
  options.noise_sigma = 0.0f;
  const FrameLighting light;
  const cv::Mat left = RenderView(scene, shader, camera, world_from_cam, light, 1, options);
  const cv::Mat right =
      RenderView(scene, shader, camera, world_from_cam * left_from_right, light, 1, options);
  const auto stereo = camera.ProjectStereo(world_from_cam.Inverse() * marker);
  ASSERT_TRUE(stereo.has_value());
  const Eigen::Vector2d expected_left(stereo->x(), stereo->y()),
      expected_right(stereo->z(), stereo->y());
  // The black 0.5 m square is ~18 px wide at 20 m, its white frame 35 px: a 27 px window sees
  // the whole square and only white around it.
  EXPECT_LT((DarkCentroid(left, expected_left, 13) - expected_left).norm(), 0.15)
      << DarkCentroid(left, expected_left, 13).transpose() << " vs " << expected_left.transpose();
  EXPECT_LT((DarkCentroid(right, expected_right, 13) - expected_right).norm(), 0.15);
  EXPECT_NEAR(expected_left.x() - expected_right.x(), camera.fx * camera.baseline / 19.7, 1.0);
}

TEST(RenderTest, NoiseHasTheRequestedSigma) {
  World world;
  Quad wall;  // a uniform grey wall filling the view
  wall.origin = Eigen::Vector3d(5, 50, -50);
  wall.edge_u = Eigen::Vector3d(0, -100, 0);
  wall.edge_v = Eigen::Vector3d(0, 0, 100);
  wall.material = Material::kMetal;
  world.AddClutterQuad(wall);
  const Scene scene(world);
  const TextureBank bank = TextureBank::Procedural(1);
  const Shader shader(world, bank);
  const Rigid3d world_from_cam(VehicleFromCamRotation(), Eigen::Vector3d(0, 0, 1.65));
  const cv::Mat image =
      RenderView(scene, shader, Kitti07Camera(), world_from_cam, FrameLighting(), 9);
  cv::Scalar mean, stddev;
  cv::meanStdDev(image, mean, stddev);
  EXPECT_NEAR(stddev[0], 2.0, 0.2);
  EXPECT_GT(mean[0], 50.0);
  EXPECT_LT(mean[0], 220.0);
}

TEST(RenderTest, ChangingLightingVariesExposureAndSun) {
  const FrameLighting a = LightingForFrame(Lighting::kChanging, 1, 0);
  const FrameLighting b = LightingForFrame(Lighting::kChanging, 1, 300);
  EXPECT_TRUE(a.shadows);
  EXPECT_GT(std::abs(a.exposure - b.exposure) + std::abs(a.sun - b.sun), 0.02);
  EXPECT_GT((a.to_sun - b.to_sun).norm(), 0.3);  // the shadows move
  const FrameLighting c = LightingForFrame(Lighting::kConstant, 1, 0);
  const FrameLighting d = LightingForFrame(Lighting::kConstant, 1, 300);
  EXPECT_FALSE(c.shadows);
  EXPECT_EQ(c.exposure, d.exposure);
  EXPECT_EQ(c.to_sun, d.to_sun);
}

TEST(RenderTest, LidarFollowsTheHdl64Pattern) {
  World world;
  Quad ground;
  ground.origin = Eigen::Vector3d(-300, -300, 0);
  ground.edge_u = Eigen::Vector3d(600, 0, 0);
  ground.edge_v = Eigen::Vector3d(0, 600, 0);
  ground.material = Material::kAsphalt;
  world.AddPlanarQuad(ground, "ground");
  const Scene scene(world);
  const TextureBank bank = TextureBank::Procedural(1);
  const Shader shader(world, bank);
  const Rigid3d world_from_velo(Eigen::Matrix3d::Identity(), Eigen::Vector3d(0, 0, 1.73));
  const VelodyneScan scan = ScanLidar(scene, shader, world_from_velo, 5);
  // Beams below -0.83 degrees reach the ground within 120 m: 57 of 64 rings, 2250 steps each.
  EXPECT_EQ(scan.points.size(), 57u * 2250u);
  double max_range = 0.0;
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    EXPECT_NEAR(scan.points[i].z(), -1.73, 0.1 + 0.02 * scan.points[i].norm()) << i;
    EXPECT_GE(scan.reflectance[i], 0.0f);
    EXPECT_LE(scan.reflectance[i], 1.0f);
    max_range = std::max(max_range, scan.points[i].norm());
  }
  EXPECT_LT(max_range, 120.1);
  // The lowest ring (-24.8 degrees) hits the road 1.73 / tan(24.8) = 3.75 m away.
  EXPECT_NEAR(scan.points.back().head<2>().norm(), 1.73 / std::tan(24.8 * M_PI / 180.0), 0.1);
}

}  // namespace
}  // namespace planeloc::sim
