#include "planeloc/optim/robust_gauss_newton.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include "planeloc/geometry/lie.h"
#include "planeloc/geometry/plane.h"

namespace planeloc {
namespace {

using Vector6 = HuberNormalEquations<6>::Vector;
using Matrix6 = HuberNormalEquations<6>::Matrix;

constexpr double kDegree = std::numbers::pi / 180.0;
constexpr double kSigma = 0.01;  // metres, the inliers' noise

// Points on six planes of different orientation (a ground, walls, a slanted roof), observed in
// a frame that is off by a known rigid offset; every tenth point is clutter 0.3-1.5 m in front
// of its plane (one-sided, as in front of a wall: it biases least squares).
struct PointToPlaneScene {
  std::vector<Plane> planes;
  std::vector<Eigen::Vector3d> points;  // observed frame
  std::vector<int> plane_of_point;
  Eigen::Matrix3d rotation;  // true offset: p_plane_frame = rotation p + shift
  Eigen::Vector3d shift;
};

PointToPlaneScene MakeScene() {
  PointToPlaneScene scene;
  scene.planes = {
      Plane(Eigen::Vector3d(0, 0, 1), 0.0),     Plane(Eigen::Vector3d(1, 0, 0), -8.0),
      Plane(Eigen::Vector3d(-1, 0, 0), -7.0),   Plane(Eigen::Vector3d(0, 1, 0), -12.0),
      Plane(Eigen::Vector3d(0.3, -1, 0), -9.0), Plane(Eigen::Vector3d(0.2, 0.3, 1), -6.0)};
  scene.rotation = ExpSO3(Eigen::Vector3d(0.5, -1.0, 3.0) * kDegree);
  scene.shift = Eigen::Vector3d(0.4, -0.3, 0.2);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> in_plane(-6.0, 6.0), clutter(0.3, 1.5);
  std::normal_distribution<double> noise(0.0, kSigma);
  for (int p = 0; p < static_cast<int>(scene.planes.size()); ++p) {
    const Plane& plane = scene.planes[p];
    const auto [u, v] = plane.InPlaneBasis();
    const Eigen::Vector3d origin = -plane.d * plane.normal;
    for (int i = 0; i < 150; ++i) {
      const double offset = i % 10 == 0 ? clutter(rng) : noise(rng);
      const Eigen::Vector3d in_plane_frame =
          origin + in_plane(rng) * u + in_plane(rng) * v + offset * plane.normal;
      scene.points.push_back(scene.rotation.transpose() * (in_plane_frame - scene.shift));
      scene.plane_of_point.push_back(p);
    }
  }
  return scene;
}

struct Estimate {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  int steps = 0;
};

// Point-to-plane Gauss-Newton from the identity, in (shift, rotation vector), left-multiplied.
Estimate Solve(const PointToPlaneScene& scene, double huber_threshold, int iterations,
               const Matrix6& prior_information = Matrix6::Zero()) {
  Estimate estimate;
  estimate.steps = RobustGaussNewton<6>(
      iterations, huber_threshold, prior_information,
      [&](int, HuberNormalEquations<6>& equations) {
        for (std::size_t i = 0; i < scene.points.size(); ++i) {
          const Plane& plane = scene.planes[scene.plane_of_point[i]];
          const Eigen::Vector3d q = estimate.rotation * scene.points[i];
          HuberNormalEquations<6>::Row jacobian;
          jacobian.head<3>() = plane.normal.transpose();
          jacobian.tail<3>() = -plane.normal.transpose() * Hat(q);
          equations.Add(plane.SignedDistance(q + estimate.shift) / kSigma, jacobian / kSigma);
        }
        Vector6 deviation;
        deviation << estimate.shift, LogSO3(estimate.rotation);
        return deviation;
      },
      [&](const Vector6& step) {
        estimate.shift += step.head<3>();
        estimate.rotation = ExpSO3(step.tail<3>()) * estimate.rotation;
      });
  return estimate;
}

double ShiftError(const Estimate& estimate, const PointToPlaneScene& scene) {
  return (estimate.shift - scene.shift).norm();
}
double AngleErrorDeg(const Estimate& estimate, const PointToPlaneScene& scene) {
  return LogSO3(estimate.rotation * scene.rotation.transpose()).norm() / kDegree;
}

TEST(RobustGaussNewtonTest, RecoversASixDofOffsetOfPointToPlaneDataWithOutliers) {
  const PointToPlaneScene scene = MakeScene();
  const Estimate robust = Solve(scene, 2.0, 10);
  EXPECT_EQ(robust.steps, 10);
  // Huber bounds the clutter's pull, it does not remove it: about 2.5 mm (1/9 of the points at
  // 2 sigma each) remain; least squares is 9 cm off.
  EXPECT_LT(ShiftError(robust, scene), 0.005);
  EXPECT_LT(AngleErrorDeg(robust, scene), 0.05);
  // The same data in least squares: the clutter pulls the planes towards it by decimetres, so the
  // Huber weights are what makes the answer right.
  const Estimate least_squares = Solve(scene, std::numeric_limits<double>::infinity(), 10);
  EXPECT_GT(ShiftError(least_squares, scene), 0.03);
}

TEST(RobustGaussNewtonTest, HuberWeightIsThresholdOverResidualBeyondTheThreshold) {
  HuberNormalEquations<2> equations(2.0);
  equations.Add(1.0, HuberNormalEquations<2>::Row(1.0, 0.0));   // inside: weight 1
  equations.Add(-4.0, HuberNormalEquations<2>::Row(0.0, 2.0));  // outside: weight 2 / 4
  EXPECT_DOUBLE_EQ(equations.hessian()(0, 0), 1.0);
  EXPECT_DOUBLE_EQ(equations.hessian()(1, 1), 0.5 * 4.0);
  EXPECT_DOUBLE_EQ(equations.hessian()(0, 1), 0.0);
  EXPECT_DOUBLE_EQ(equations.gradient()(0), 1.0);
  EXPECT_DOUBLE_EQ(equations.gradient()(1), 0.5 * 2.0 * -4.0);
}

TEST(RobustGaussNewtonTest, PriorAloneReturnsToItsMean) {
  const HuberNormalEquations<2> no_data(2.0);
  const HuberNormalEquations<2>::Matrix information =
      HuberNormalEquations<2>::Matrix::Identity() * 4.0;
  const HuberNormalEquations<2>::Vector step =
      no_data.Step(information, HuberNormalEquations<2>::Vector(0.3, -0.2));
  EXPECT_NEAR(step(0), -0.3, 1e-15);
  EXPECT_NEAR(step(1), 0.2, 1e-15);
}

TEST(RobustGaussNewtonTest, StopsAtTheFirstNonFiniteStep) {
  // A residual that became NaN (a degenerate linearization) ends the iteration, unapplied.
  int linearized = 0, applied = 0;
  const Matrix6 information = Matrix6::Identity();
  const int steps = RobustGaussNewton<6>(
      5, 2.0, information,
      [&](int k, HuberNormalEquations<6>& equations) {
        ++linearized;
        const HuberNormalEquations<6>::Row jacobian = HuberNormalEquations<6>::Row::Ones();
        equations.Add(k == 0 ? 0.5 : std::numeric_limits<double>::quiet_NaN(), jacobian);
        return Vector6::Zero().eval();
      },
      [&](const Vector6& step) {
        EXPECT_TRUE(step.allFinite());
        ++applied;
      });
  EXPECT_EQ(linearized, 2);
  EXPECT_EQ(applied, 1);
  EXPECT_EQ(steps, 1);
}

}  // namespace
}  // namespace planeloc
