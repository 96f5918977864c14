#include "planeloc/sim/simulator.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <fstream>
#include <iterator>
#include <memory>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>

#include "planeloc/io/kitti_sequence.h"
#include "planeloc/io/plane_map.h"
#include "planeloc/util/error.h"
#include "planeloc/util/temp_dir.h"

namespace planeloc::sim {
namespace {

namespace fs = std::filesystem;

SimOptions Tiny(int frames) {
  SimOptions options = SimOptions::FromPreset("tiny");
  options.frames = frames;
  options.show_progress = false;
  return options;
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::size_t CountFiles(const fs::path& dir) {
  return static_cast<std::size_t>(
      std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

// One tiny 3-frame sequence shared by the tests of this file (rendering takes ~1 s a frame).
class SimulatorTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>("planeloc-sim");
    result_ = std::make_unique<SimResult>(GenerateSequence(Tiny(3), dir_->path()));
  }
  static void TearDownTestSuite() {
    result_.reset();
    dir_.reset();
  }
  static std::unique_ptr<TempDir> dir_;
  static std::unique_ptr<SimResult> result_;
};
std::unique_ptr<TempDir> SimulatorTest::dir_;
std::unique_ptr<SimResult> SimulatorTest::result_;

TEST_F(SimulatorTest, WritesTheKittiOdometryLayout) {
  const fs::path seq = dir_->path() / "sequences" / "00";
  EXPECT_EQ(result_->sequence_dir, seq);
  EXPECT_EQ(CountFiles(seq / "image_0"), 3u);
  EXPECT_EQ(CountFiles(seq / "image_1"), 3u);
  EXPECT_EQ(CountFiles(seq / "velodyne"), 3u);
  EXPECT_TRUE(fs::exists(dir_->path() / "poses" / "00.txt"));
  EXPECT_TRUE(fs::exists(dir_->path() / "world" / "README.txt"));
  const cv::Mat image = cv::imread((seq / "image_1" / "000002.png").string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(image.type(), CV_8UC1);
  EXPECT_EQ(image.cols, 1226);
  EXPECT_EQ(image.rows, 370);
  const std::string readme = ReadBytes(dir_->path() / "world" / "README.txt");
  EXPECT_NE(readme.find("preset: tiny"), std::string::npos);
  EXPECT_NE(readme.find("seed: 1"), std::string::npos);
  EXPECT_NE(readme.find("lighting: constant"), std::string::npos);
}

TEST_F(SimulatorTest, CalibrationIsKitti07) {
  std::ifstream calib(result_->sequence_dir / "calib.txt");
  std::string name;
  std::map<std::string, std::vector<double>> rows;
  for (std::string line; std::getline(calib, line);) {
    std::istringstream fields(line);
    fields >> name;
    for (double v; fields >> v;) rows[name].push_back(v);
  }
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_DOUBLE_EQ(rows["P0:"][0], 707.0912);
  EXPECT_DOUBLE_EQ(rows["P0:"][5], 707.0912);
  EXPECT_DOUBLE_EQ(rows["P0:"][2], 601.8873);
  EXPECT_DOUBLE_EQ(rows["P0:"][6], 183.1104);
  EXPECT_NEAR(rows["P1:"][3], -707.0912 * 0.537, 1e-9);
  EXPECT_DOUBLE_EQ(rows["Tr:"][0], -1.857739385241e-03);
  EXPECT_DOUBLE_EQ(rows["Tr:"][11], -3.339968064433e-01);
  // The project's reader agrees.
  const KittiSequence sequence = KittiSequence::Open(result_->sequence_dir);
  ASSERT_EQ(sequence.size(), 3u);
  EXPECT_NEAR(sequence.camera().baseline, 0.537, 1e-12);
  EXPECT_EQ(sequence.camera().width, 1226);
  EXPECT_NEAR(sequence.timestamp(2), 0.2, 1e-9);
  ASSERT_TRUE(sequence.cam_from_velo().has_value());
  EXPECT_LT((sequence.cam_from_velo()->translation - Kitti07CamFromVelo().translation).norm(),
            1e-12);
  ASSERT_TRUE(sequence.ground_truth().has_value());
  ASSERT_EQ(sequence.ground_truth()->size(), 3u);
  EXPECT_LT(sequence.ground_truth()->front().translation.norm(), 1e-12);
  EXPECT_LT(
      RotationAngle(sequence.ground_truth()->front().rotation, Eigen::Quaterniond::Identity()),
      1e-12);
  // Driving forward along +z at 5..12 m/s.
  const Eigen::Vector3d step = (*sequence.ground_truth())[1].translation;
  EXPECT_GT(step.z(), 0.5);
  EXPECT_LT(step.z(), 1.2);
  EXPECT_LT(std::abs(step.x()) + std::abs(step.y()), 0.1);
}

TEST_F(SimulatorTest, GtPlanePolygonsLieOnTheirPlanes) {
  const PlaneMap map = ReadPlaneMap(result_->planes_path);
  int ground = 0, facades = 0;
  for (const MapPlane& p : map.planes) {
    EXPECT_NEAR(p.plane_in_map.normal.norm(), 1.0, 1e-9);
    ASSERT_GE(p.polygon.size(), 3u);
    for (const auto& corner : p.polygon) {
      EXPECT_NEAR(p.plane_in_map.SignedDistance(corner), 0.0, 1e-6) << "plane " << p.id;
    }
    ground += p.kind == "ground";
    facades += p.kind == "facade";
    EXPECT_TRUE(p.kind == "ground" || p.kind == "facade" || p.kind == "other") << p.kind;
  }
  EXPECT_GE(ground, 1);
  EXPECT_GE(facades, 20);
  // The road (plane 0) is 1.65 m below the first camera, facing up (-y in KITTI camera axes).
  const Plane road = map.planes.front().plane_in_map;
  EXPECT_NEAR(std::abs(road.d), 1.65, 0.05);
  EXPECT_LT(road.normal.y() * road.d, 0.0);
}

// Distance from `point` to the convex polygon of a GT plane, or infinity outside its outline.
double DistanceInsidePolygon(const MapPlane& p, const Eigen::Vector3d& point) {
  const Eigen::Vector3d n = p.plane_in_map.normal;
  const Eigen::Vector3d on = p.plane_in_map.Project(point);
  const std::size_t k = p.polygon.size();
  double sign = 0.0;
  for (std::size_t i = 0; i < k; ++i) {
    const double s = n.dot((p.polygon[(i + 1) % k] - p.polygon[i]).cross(on - p.polygon[i]));
    if (sign == 0.0) sign = s;
    if (s * sign < 0.0) return std::numeric_limits<double>::infinity();
  }
  return std::abs(p.plane_in_map.SignedDistance(point));
}

TEST_F(SimulatorTest, LidarReturnsLieOnGtPlanesOrClutter) {
  const VelodyneScan scan = ReadVelodyneScan(result_->sequence_dir / "velodyne" / "000001.bin");
  ASSERT_GT(scan.points.size(), 100000u);  // HDL-64E: ~120k returns in a street
  const PlaneMap map = ReadPlaneMap(result_->planes_path);
  const Scenario scenario = BuildScenario(Tiny(3));
  // Poses frame (= planes frame) and the simulator's world frame.
  const Rigid3d cam0_from_velo = result_->world_from_cam[1] * result_->cam_from_velo;
  const Rigid3d world_from_velo = scenario.world_from_cam[1] * result_->cam_from_velo;
  int on_plane = 0, on_surface = 0, tested = 0;
  double sum_abs = 0.0;
  for (std::size_t i = 0; i < scan.points.size(); i += 97) {
    ++tested;
    double best = std::numeric_limits<double>::infinity();
    for (const MapPlane& p : map.planes)
      best = std::min(best, DistanceInsidePolygon(p, cam0_from_velo * scan.points[i]));
    on_plane += best < 0.06;
    const double d = scenario.world.DistanceToSurface(world_from_velo * scan.points[i]);
    on_surface += d < 0.06;
    sum_abs += std::min(d, 1.0);
  }
  EXPECT_GT(on_surface, 0.97 * tested);  // within 3 sigma of the 2 cm range noise
  EXPECT_GT(on_plane, 0.6 * tested);     // the rest hits trees, cars, poles
  const double mean_abs = sum_abs / tested;
  EXPECT_GT(mean_abs, 0.003);  // there is range noise ...
  EXPECT_LT(mean_abs, 0.03);   // ... of about 2 cm along the beam
}

TEST_F(SimulatorTest, OrbFindsKittiLikeFeatureCounts) {
  const cv::Mat image =
      cv::imread((result_->sequence_dir / "image_0" / "000000.png").string(), cv::IMREAD_GRAYSCALE);
  std::vector<cv::KeyPoint> keypoints;
  cv::ORB::create(3000)->detect(image, keypoints);
  EXPECT_GE(keypoints.size(), 1000u);
}

// The first N frames do not depend on N or on the number of threads: byte-identical files.
TEST_F(SimulatorTest, DeterministicAcrossRunsAndThreadCounts) {
  for (int threads : {1, 2}) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    TempDir dir("planeloc-sim-repeat");
    GenerateSequence(Tiny(2), dir.path());
    for (const char* file : {"image_0/000000.png", "image_1/000001.png", "velodyne/000001.bin"}) {
      EXPECT_EQ(ReadBytes(dir.path() / "sequences" / "00" / file),
                ReadBytes(result_->sequence_dir / file))
          << file << " with " << threads << " threads";
    }
    EXPECT_EQ(ReadBytes(dir.path() / "world" / "planes_gt.json"), ReadBytes(result_->planes_path));
    std::istringstream poses(ReadBytes(dir.path() / "poses" / "00.txt"));
    std::istringstream reference(ReadBytes(result_->poses_path));
    for (int line = 0; line < 2; ++line) {
      std::string a, b;
      std::getline(poses, a);
      std::getline(reference, b);
      EXPECT_EQ(a, b) << "pose " << line;
    }
  }
}

TEST(SimulatorOptionsTest, BadInputIsAnInputError) {
  EXPECT_THROW(SimOptions::FromPreset("huge"), InputError);
  for (int frames : {0, -3}) EXPECT_THROW(Tiny(frames).Check(), InputError);
  EXPECT_THROW(ParseLighting("dusk"), InputError);
  SimOptions options = Tiny(1);
  options.texture_dir = "/nonexistent/planeloc/textures";
  EXPECT_THROW(options.Check(), InputError);
  TempDir empty_textures("planeloc-sim-tex");
  options.texture_dir = empty_textures.path();
  TempDir out("planeloc-sim-out");
  EXPECT_THROW(GenerateSequence(options, out.path() / "a"), InputError);  // no image inside
  options = Tiny(1);
  options.trajectory_path = "/nonexistent/poses.txt";
  EXPECT_THROW(options.Check(), InputError);
  std::ofstream(out.path() / "bad_poses.txt") << "1 0 0 0 0 1 0 0 0 0 1\n";
  options.trajectory_path = out.path() / "bad_poses.txt";
  EXPECT_THROW(BuildScenario(options), InputError);
}

TEST(SimulatorOptionsTest, RefusesANonEmptyOutputFolderUnlessForced) {
  TempDir out("planeloc-sim-out");
  std::ofstream(out.path() / "keep.txt") << "user data\n";
  EXPECT_THROW(GenerateSequence(Tiny(1), out.path()), InputError);
  const SimResult result = GenerateSequence(Tiny(1), out.path(), /*force=*/true);
  EXPECT_EQ(result.frames, 1);
  EXPECT_TRUE(fs::exists(out.path() / "keep.txt"));  // only the simulator's own files go
  EXPECT_EQ(CountFiles(result.sequence_dir / "image_0"), 1u);
}

}  // namespace
}  // namespace planeloc::sim
