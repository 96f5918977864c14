#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <random>

#include "planeloc/geometry/camera.h"
#include "planeloc/geometry/lie.h"
#include "planeloc/geometry/plane.h"
#include "planeloc/geometry/rigid3.h"

namespace planeloc {
namespace {

Rigid3d RandomTransform(std::mt19937& rng, double max_angle = 3.0) {
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  const Eigen::Vector3d axis =
      Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)).normalized();
  const double angle = max_angle * std::abs(uniform(rng));
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis)),
                 Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)) * 10.0);
}

TEST(Rigid3d, InverseAndComposition) {
  std::mt19937 rng(1);
  for (int i = 0; i < 100; ++i) {
    const Rigid3d b_from_a = RandomTransform(rng);
    const Rigid3d c_from_b = RandomTransform(rng);
    const Eigen::Vector3d point_in_a(1.0, -2.0, 3.0);
    EXPECT_LT(((b_from_a.Inverse() * b_from_a) * point_in_a - point_in_a).norm(), 1e-12);
    EXPECT_LT(((c_from_b * b_from_a) * point_in_a - c_from_b * (b_from_a * point_in_a)).norm(),
              1e-10);
    const Rigid3d from_matrix = Rigid3d::FromMatrix3x4(b_from_a.Matrix3x4());
    EXPECT_LT((from_matrix.Matrix4d() - b_from_a.Matrix4d()).norm(), 1e-12);
  }
}

TEST(Lie, So3RoundTrip) {
  std::mt19937 rng(2);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d omega =
        Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng)).normalized() *
        (3.1 * std::abs(uniform(rng)));
    EXPECT_LT((LogSO3(ExpSO3(omega)) - omega).norm(), 1e-9);
    const Eigen::Matrix3d r = ExpSO3(omega);
    EXPECT_LT((r * r.transpose() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    EXPECT_NEAR(r.determinant(), 1.0, 1e-12);
  }
  const Eigen::Vector3d tiny(1e-10, -2e-10, 3e-10);
  EXPECT_LT((LogSO3(ExpSO3(tiny)) - tiny).norm(), 1e-18);
}

TEST(Lie, So3MatchesAngleAxis) {
  const Eigen::Vector3d omega(0.3, -0.2, 0.9);
  const Eigen::Matrix3d expected = Eigen::AngleAxisd(omega.norm(), omega.normalized()).matrix();
  EXPECT_LT((ExpSO3(omega) - expected).norm(), 1e-12);
}

TEST(Lie, Se3RoundTrip) {
  std::mt19937 rng(3);
  for (int i = 0; i < 200; ++i) {
    const Rigid3d transform = RandomTransform(rng, 3.0);
    const Rigid3d back = ExpSE3(LogSE3(transform));
    EXPECT_LT((back.Matrix4d() - transform.Matrix4d()).norm(), 1e-9);
  }
  // A pure translation has rho = translation.
  Vector6d xi;
  xi << 1, 2, 3, 0, 0, 0;
  EXPECT_LT((ExpSE3(xi).translation - Eigen::Vector3d(1, 2, 3)).norm(), 1e-15);
}

TEST(Lie, InverseLeftJacobian) {
  const Eigen::Vector3d omega(0.4, 0.1, -0.7);
  EXPECT_LT(
      (LeftJacobianSO3(omega) * InverseLeftJacobianSO3(omega) - Eigen::Matrix3d::Identity()).norm(),
      1e-12);
}

Eigen::Matrix<double, 3, 4> KittiProjection(double fx, double cx, double cy, double tx) {
  Eigen::Matrix<double, 3, 4> p;
  p << fx, 0, cx, tx, 0, fx, cy, 0, 0, 0, 1, 0;
  return p;
}

TEST(StereoCamera, FromKitti07Projections) {
  // KITTI odometry sequence 07 calib: P1(0,3) = -fx * b.
  const auto p0 = KittiProjection(707.0912, 601.8873, 183.1104, 0.0);
  const auto p1 = KittiProjection(707.0912, 601.8873, 183.1104, -379.8145);
  const StereoCamera camera = StereoCamera::FromProjections(p0, p1, 1226, 370);
  EXPECT_NEAR(camera.baseline, 379.8145 / 707.0912, 1e-12);
  EXPECT_NEAR(camera.baseline, 0.537, 1e-3);
  const Eigen::Vector3d point(1.0, -0.5, 10.0);
  const Eigen::Vector3d stereo = *camera.ProjectStereo(point);
  EXPECT_NEAR(stereo.x() - stereo.z(), camera.fx * camera.baseline / 10.0, 1e-9);
  EXPECT_NEAR(camera.DepthFromDisparity(stereo.x() - stereo.z()), 10.0, 1e-9);
  EXPECT_LT((camera.Unproject(stereo.head<2>(), 10.0) - point).norm(), 1e-12);
  EXPECT_FALSE(camera.Project(Eigen::Vector3d(0, 0, -1)).has_value());
}

TEST(StereoCamera, RejectsZeroBaseline) {
  const auto p0 = KittiProjection(700, 600, 180, 0.0);
  EXPECT_THROW(StereoCamera::FromProjections(p0, p0, 100, 100), std::invalid_argument);
}

TEST(Plane, FitTransformAndDistance) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> uniform(-5.0, 5.0);
  const Plane truth(Eigen::Vector3d(0.2, -0.9, 0.1), 3.0);
  EXPECT_NEAR(truth.normal.norm(), 1.0, 1e-15);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 50; ++i) {
    points.push_back(truth.Project(Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng))));
  }
  Plane fitted = Plane::Fit(points);
  if (fitted.normal.dot(truth.normal) < 0) fitted = fitted.Flipped();
  EXPECT_LT((fitted.normal - truth.normal).norm(), 1e-9);
  EXPECT_NEAR(fitted.d, truth.d, 1e-9);

  const Rigid3d b_from_a = RandomTransform(rng);
  const Plane in_b = truth.Transformed(b_from_a);
  for (const auto& p : points) EXPECT_NEAR(in_b.SignedDistance(b_from_a * p), 0.0, 1e-9);
  EXPECT_NEAR(truth.AngleTo(truth.Flipped()), 0.0, 1e-12);
  EXPECT_THROW(
      Plane::Fit({Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), Eigen::Vector3d(2, 0, 0)}),
      std::invalid_argument);
}

TEST(PolygonTest, IndexedOutlineAnswersAsTheFullScan) {
  // Star-shaped, non-convex rings with 5 to 200 vertices (LiDAR outlines are of that kind),
  // queried in and around their box, exactly on vertices and edges' y, with margins 0 to 0.5.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int inside = 0, near = 0, outside = 0;
  for (int trial = 0; trial < 40; ++trial) {
    const int n = 5 + static_cast<int>(unit(rng) * 195);
    std::vector<Eigen::Vector2d> ring;
    for (int i = 0; i < n; ++i) {
      const double angle = 2.0 * M_PI * i / n;
      const double radius = 2.0 + 8.0 * unit(rng);
      ring.emplace_back(radius * std::cos(angle), 0.3 * radius * std::sin(angle));
    }
    const IndexedPolygon2d indexed(ring);
    std::vector<Eigen::Vector2d> queries;
    for (int k = 0; k < 400; ++k) {
      queries.emplace_back(-12 + 24 * unit(rng), -4 + 8 * unit(rng));
    }
    for (const Eigen::Vector2d& v : ring) {
      queries.push_back(v);
      queries.emplace_back(v.x() + 0.2, v.y());
    }
    for (const double margin : {0.0, 0.1, 0.5}) {
      for (const Eigen::Vector2d& q : queries) {
        const bool expected = InsideOrNearPolygon2d(ring, q, margin);
        ASSERT_EQ(indexed.InsideOrNear(q, margin), expected)
            << "trial " << trial << ", " << n << " vertices, q " << q.transpose() << ", margin "
            << margin;
        if (!expected) {
          ++outside;
        } else if (InsidePolygon2d(ring, q)) {
          ++inside;
        } else {
          ++near;
        }
      }
    }
  }
  // All three answers occurred (the comparison is not vacuous).
  EXPECT_GT(inside, 1000);
  EXPECT_GT(near, 100);
  EXPECT_GT(outside, 1000);
  EXPECT_FALSE(IndexedPolygon2d({{0, 0}, {1, 0}}).InsideOrNear({0.5, 0}, 1.0));
  EXPECT_FALSE(IndexedPolygon2d({{0, 0}, {1, 0}, {0, 1}}).InsideOrNear({1e300, -1e300}, 0.5));
}

}  // namespace
}  // namespace planeloc

namespace planeloc {
namespace {

TEST(PolygonTest, InsideOrNearGrowsTheOutlineByTheMargin) {
  const std::vector<Eigen::Vector2d> square = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  EXPECT_TRUE(InsideOrNearPolygon2d(square, {0.5, 0.5}, 0.0));
  EXPECT_TRUE(InsideOrNearPolygon2d(square, {1.3, 0.5}, 0.5));   // 0.3 from the right edge
  EXPECT_FALSE(InsideOrNearPolygon2d(square, {1.6, 0.5}, 0.5));  // 0.6
  // Beyond a corner the distance is to the corner: 0.3 * sqrt(2) = 0.42, 0.4 * sqrt(2) = 0.57.
  EXPECT_TRUE(InsideOrNearPolygon2d(square, {1.3, 1.3}, 0.5));
  EXPECT_FALSE(InsideOrNearPolygon2d(square, {1.4, 1.4}, 0.5));
}

}  // namespace
}  // namespace planeloc
