#include "planeloc/sim/render.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
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

// EuRoC's cam0 (752x480) looking along +x from 6 m in front of the marker wall, the marker off to
// the upper right where the lens's barrel distortion moves it by tens of pixels.
struct DistortedView {
  StereoCamera camera;
  Eigen::Vector4d distortion{-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05};
  Rigid3d world_from_cam;
  DistortedView() {
    camera.fx = 458.654;
    camera.fy = 457.296;
    camera.cx = 367.215;
    camera.cy = 248.375;
    camera.width = 752;
    camera.height = 480;
    world_from_cam = Rigid3d(VehicleFromCamRotation(), Eigen::Vector3d(14.0, 0.0, 1.65));
  }
  // Where OpenCV's model (the one the ASL reader's rectifier inverts) puts a world point.
  Eigen::Vector2d Project(const Eigen::Vector3d& world_point, bool distorted) const {
    const Eigen::Vector3d p = world_from_cam.Inverse() * world_point;
    cv::Mat k =
        (cv::Mat_<double>(3, 3) << camera.fx, 0, camera.cx, 0, camera.fy, camera.cy, 0, 0, 1);
    cv::Mat d = cv::Mat::zeros(1, 4, CV_64F);
    if (distorted) {
      for (int i = 0; i < 4; ++i) d.at<double>(0, i) = distortion[i];
    }
    std::vector<cv::Point2d> image;
    cv::projectPoints(std::vector<cv::Point3d>{{p.x(), p.y(), p.z()}}, cv::Vec3d(0, 0, 0),
                      cv::Vec3d(0, 0, 0), k, d, image);
    return Eigen::Vector2d(image[0].x, image[0].y);
  }
};

TEST(RenderTest, DistortedMarkerAppearsWhereTheLensModelProjectsIt) {
  // Normalized coordinates (0.55, -0.3) at 6 m: radius^2 0.39, where k1 = -0.28 pulls the point
  // 10 % towards the centre (25 px in x, 14 px in y).
  const Eigen::Vector3d marker(20.0, -3.3, 3.45);
  const World world = MarkerWorld(marker);
  const Scene scene(world);
  const TextureBank bank = TextureBank::Procedural(1);
  const Shader shader(world, bank);
  const DistortedView view;
  CameraRenderOptions options;
  options.noise_sigma = 0.0f;
  options.distortion = view.distortion;
  const cv::Mat image =
      RenderView(scene, shader, view.camera, view.world_from_cam, FrameLighting(), 1, options);
  const Eigen::Vector2d distorted = view.Project(marker, true);
  const Eigen::Vector2d pinhole = view.Project(marker, false);
  ASSERT_GT((distorted - pinhole).norm(), 20.0);  // the test can tell the two models apart
  // The 0.5 m square is ~38 px wide; the centroid of its distorted image is the projection of
  // its centre to second order (measured 0.19 px; the pinhole projection is 20+ px away).
  const Eigen::Vector2d found = DarkCentroid(image, distorted, 27);
  EXPECT_LT((found - distorted).norm(), 0.35)
      << found.transpose() << " vs " << distorted.transpose();
  // The same pixel-exact path as the blurred renderer when nothing moves.
  const cv::Mat still = RenderViewDuringExposure(scene, shader, view.camera, view.world_from_cam,
                                                 view.world_from_cam, FrameLighting(), 1, options);
  EXPECT_LT((DarkCentroid(still, distorted, 27) - distorted).norm(), 0.35);
}

// A camera panning during the exposure smears vertical edges (across the motion) and leaves
// horizontal ones sharp.
TEST(RenderTest, MotionBlurSmearsAlongTheMotionOnly) {
  const Eigen::Vector3d marker(20.0, 0.0, 1.65);
  const World world = MarkerWorld(marker);
  const Scene scene(world);
  const TextureBank bank = TextureBank::Procedural(1);
  const Shader shader(world, bank);
  DistortedView view;
  view.world_from_cam.translation = Eigen::Vector3d(16.0, 0.0, 1.65);  // marker ~57 px wide
  CameraRenderOptions options;
  options.noise_sigma = 0.0f;
  options.supersampling = 4;  // 16 sample times over the exposure
  // 1.5 degrees about the vertical during the exposure: 12 px of smear at fx 459.
  const Rigid3d panned(
      Eigen::Quaterniond(Eigen::AngleAxisd(1.5 * M_PI / 180.0, Eigen::Vector3d::UnitZ())) *
          view.world_from_cam.rotation,
      view.world_from_cam.translation);
  const cv::Mat still = RenderViewDuringExposure(scene, shader, view.camera, view.world_from_cam,
                                                 view.world_from_cam, FrameLighting(), 1, options);
  const cv::Mat moving = RenderViewDuringExposure(scene, shader, view.camera, view.world_from_cam,
                                                  panned, FrameLighting(), 1, options);
  const auto peak = [&](const cv::Mat& image, int dx, int dy) {
    cv::Mat grad;
    cv::Sobel(image, grad, CV_32F, dx, dy);
    double max_value = 0.0;
    cv::minMaxLoc(cv::abs(grad), nullptr, &max_value);
    return max_value;
  };
  ASSERT_GT(peak(still, 1, 0), 100.0);
  // Measured: the horizontal gradient's peak falls to 0.19 of the still image's, the vertical
  // one's stays (1.00).
  EXPECT_LT(peak(moving, 1, 0), 0.4 * peak(still, 1, 0));
  EXPECT_GT(peak(moving, 0, 1), 0.8 * peak(still, 0, 1));
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
