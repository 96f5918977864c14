#include "planeloc/map/tensor_voting.h"

#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>

#include "planeloc/map/synthetic_scene_for_test.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

using testing::SceneBuilder;

double AngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * 180.0 /
         std::numbers::pi;
}

// The paper's rule (largest of l1-l2, l2-l3, l3 wins) applied to the eigenvalues of OUR
// normal-space tensor: stick = surface, plate = curve, ball = junction.
TEST(TensorVotingTest, ClassRuleOnNormalSpaceEigenvalues) {
  EXPECT_EQ(ClassifySaliency(1.0, 0.1, 0.05), SaliencyClass::kSurface);
  EXPECT_EQ(ClassifySaliency(1.0, 0.8, 0.1), SaliencyClass::kCurve);
  EXPECT_EQ(ClassifySaliency(1.0, 0.9, 0.85), SaliencyClass::kJunction);
  EXPECT_EQ(ClassifySaliency(0.0, 0.0, 0.0), SaliencyClass::kJunction);
}

// The paper states its classes in the tangent (covariance) encoding, where a wall is a "plate"
// (two large eigenvalues spanning it, normal e3) and an edge a "stick" (one large eigenvalue
// along it). This checks the mapping to our normal-space classes on three point sets whose
// paper class is computed here, independently, from the covariance of the points around the
// centre point: plate -> kSurface, stick -> kCurve, ball -> kJunction.
TEST(TensorVotingTest, PaperTangentEncodingMapsToOurClasses) {
  std::mt19937 rng(17);
  std::normal_distribution<double> noise(0.0, 0.005);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::vector<Eigen::Vector3d> wall, edge, blob;
  for (double a = -1.0; a <= 1.0; a += 0.05) {
    for (double b = -1.0; b <= 1.0; b += 0.05) {
      wall.emplace_back(a + noise(rng), b + noise(rng), noise(rng));  // the plane z = 0
    }
    edge.emplace_back(a, noise(rng), noise(rng));  // a line along x
  }
  while (blob.size() < 1500) {  // uniform in the unit ball: clutter (a tree crown)
    const Eigen::Vector3d p(unit(rng), unit(rng), unit(rng));
    if (p.norm() <= 1.0) blob.push_back(p);
  }
  // The paper's (tangent-space) class of the neighbourhood of the point nearest the origin.
  const double radius = TensorVotingOptions().radius();
  auto paper_class = [&](const std::vector<Eigen::Vector3d>& points) {
    Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
    int n = 0;
    for (const Eigen::Vector3d& p : points) {
      if (p.norm() > radius) continue;
      covariance += p * p.transpose();
      ++n;
    }
    const Eigen::Vector3d l =
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(covariance / n).eigenvalues().reverse();
    const double stick = l(0) - l(1), plate = l(1) - l(2), ball = l(2);
    if (stick >= plate && stick >= ball) return std::string("stick");
    if (plate >= ball) return std::string("plate");
    return std::string("ball");
  };
  auto our_class = [&](const std::vector<Eigen::Vector3d>& points) {
    std::size_t centre = 0;
    for (std::size_t i = 1; i < points.size(); ++i) {
      if (points[i].norm() < points[centre].norm()) centre = i;
    }
    return RunTensorVoting(points, TensorVotingOptions()).classes[centre];
  };
  EXPECT_EQ(paper_class(wall), "plate");
  EXPECT_EQ(our_class(wall), SaliencyClass::kSurface);
  EXPECT_EQ(paper_class(edge), "stick");
  EXPECT_EQ(our_class(edge), SaliencyClass::kCurve);
  EXPECT_EQ(paper_class(blob), "ball");
  EXPECT_EQ(our_class(blob), SaliencyClass::kJunction);
}

TEST(TensorVotingTest, OptionsCheckNamesTheField) {
  TensorVotingOptions options;
  options.sigma = 0.0;
  try {
    options.Check();
    FAIL();
  } catch (const OptionsError& e) {
    EXPECT_NE(std::string(e.what()).find("sigma"), std::string::npos);
  }
  options = TensorVotingOptions();
  options.stick_passes = -1;
  EXPECT_THROW(options.Check(), OptionsError);
}

TEST(TensorVotingTest, NoisyPlaneGivesItsNormalAsStickE1) {
  SceneBuilder builder(0.1, 0.02, 5);
  const Eigen::Vector3d u = Eigen::Vector3d(1, 1, 0).normalized();
  const Eigen::Vector3d v = Eigen::Vector3d(-1, 1, 2).normalized();
  builder.Rectangle({0, 0, 0}, u, 4.0, v, 4.0, true);
  const auto& points = builder.scene().points;
  const Eigen::Vector3d normal = u.cross(v);
  const TensorVotingResult result = RunTensorVoting(points, TensorVotingOptions());
  ASSERT_EQ(result.size(), points.size());
  double sum = 0.0;
  int surface = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    sum += AngleDeg(result.normals[i], normal);
    surface += result.classes[i] == SaliencyClass::kSurface;
    EXPECT_NEAR(result.stick[i] + result.plate[i] + result.ball[i], 1.0, 1e-4);
  }
  EXPECT_LT(sum / points.size(), 1.5);
  EXPECT_GT(surface, 0.95 * points.size());
}

TEST(TensorVotingTest, StickPassKeepsNormalsSharpAtACrease) {
  // Floor z = 0 meeting a wall x = 0: points of the floor near the crease keep the floor normal,
  // where the ball pass alone (= weighted PCA) tilts them towards the wall.
  SceneBuilder builder(0.1, 0.01, 7);
  const Eigen::Vector3d x = Eigen::Vector3d::UnitX(), y = Eigen::Vector3d::UnitY(),
                        z = Eigen::Vector3d::UnitZ();
  builder.Rectangle({0, 0, 0}, x, 3.0, y, 4.0, true);
  builder.Rectangle({0, 0, 0}, y, 4.0, z, 3.0, true);
  const auto& scene = builder.scene();
  TensorVotingOptions ball_only;
  ball_only.stick_passes = 0;
  const TensorVotingResult ball = RunTensorVoting(scene.points, ball_only);
  const TensorVotingResult voted = RunTensorVoting(scene.points, TensorVotingOptions());
  double ball_error = 0.0, voted_error = 0.0;
  int count = 0;
  for (std::size_t i = 0; i < scene.points.size(); ++i) {
    const Eigen::Vector3d& p = scene.points[i];
    const double crease_distance = scene.gt_label[i] == 0 ? p.x() : p.z();
    if (crease_distance < 0.15 || crease_distance > 0.5 || p.y() < 0.8 || p.y() > 3.2) continue;
    const Eigen::Vector3d& normal = scene.gt_planes[scene.gt_label[i]].normal;
    ball_error += AngleDeg(ball.normals[i], normal);
    voted_error += AngleDeg(voted.normals[i], normal);
    ++count;
  }
  ASSERT_GT(count, 100);
  EXPECT_LT(voted_error / count, 10.0);
  EXPECT_LT(voted_error, 0.5 * ball_error);
}

TEST(TensorVotingTest, TreeCrownIsNotSurface) {
  SceneBuilder builder(0.1, 0.01, 9);
  builder.Blob({0, 0, 0}, 1.5, 5000);
  const TensorVotingResult result = RunTensorVoting(builder.scene().points, TensorVotingOptions());
  int surface = 0;
  for (const auto c : result.classes) surface += c == SaliencyClass::kSurface;
  EXPECT_LT(surface, 0.1 * result.size());
}

TEST(TensorVotingTest, IsolatedPointIsJunctionAndRunsAreIdentical) {
  const auto scene = SceneBuilder::StreetCorner(0.25, 0.02, 11);
  auto points = scene.points;
  points.push_back({100, 100, 100});
  const TensorVotingResult a = RunTensorVoting(points, TensorVotingOptions());
  const TensorVotingResult b = RunTensorVoting(points, TensorVotingOptions());
  EXPECT_EQ(a.classes.back(), SaliencyClass::kJunction);
  EXPECT_EQ(a.stick.back(), 0.0f);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.normals[i], b.normals[i]) << i;
    ASSERT_EQ(a.stick[i], b.stick[i]) << i;
  }
}

TEST(TensorVotingTest, InputOrderDoesNotChangeTheResult) {
  // RunTensorVoting votes on a Morton-sorted copy; the overload with given neighbourhoods votes in
  // the input order. Both must give the same normals and the same neighbour sets, in input order.
  const auto scene = SceneBuilder::StreetCorner(0.3, 0.02, 13);
  const TensorVotingOptions options;
  const TensorVotingResult sorted = RunTensorVoting(scene.points, options);
  // The same cap as RunTensorVoting (the tree crown's rows reach it).
  const TensorVotingResult given =
      RunTensorVoting(scene.points, options,
                      FindNeighborhoods(scene.points, options.radius(),
                                        static_cast<std::size_t>(options.max_neighbors)));
  ASSERT_EQ(sorted.size(), given.size());
  ASSERT_EQ(sorted.neighborhoods.offsets, given.neighborhoods.offsets);
  for (std::size_t i = 0; i < sorted.size(); ++i) {
    std::vector<std::int32_t> a(
        sorted.neighborhoods.indices.begin() + sorted.neighborhoods.begin(i),
        sorted.neighborhoods.indices.begin() + sorted.neighborhoods.end(i));
    std::vector<std::int32_t> b(given.neighborhoods.indices.begin() + given.neighborhoods.begin(i),
                                given.neighborhoods.indices.begin() + given.neighborhoods.end(i));
    std::sort(a.begin(), a.end());
    std::sort(b.begin(), b.end());
    ASSERT_EQ(a, b) << i;
    // Only the summation order differs.
    ASSERT_LT(AngleDeg(sorted.normals[i], given.normals[i]), 1e-3) << i;
    ASSERT_NEAR(sorted.stick[i], given.stick[i], 1e-4) << i;
    ASSERT_EQ(sorted.classes[i], given.classes[i]) << i;
  }
}

}  // namespace
}  // namespace planeloc
