// Four-part tests of every residual: zero at the truth, one hand-computed value, analytic (or
// automatic) Jacobians against numeric differentiation at seeded random poses, and a tiny solve
// that recovers a perturbed pose or point.
#include "planeloc/optim/cost_functions.h"

#include <ceres/gradient_checker.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>
#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "planeloc/optim/test_scene.h"

namespace planeloc {
namespace {

// fx = fy = 500, cx = 320, cy = 240, baseline 0.5 m (bf = 250).
PinholeStereoIntrinsics SimpleIntrinsics() { return {500.0, 500.0, 320.0, 240.0, 250.0}; }

struct PoseParams {
  double q[4];
  double t[3];
  explicit PoseParams(const Rigid3d& cam_from_world) {
    const Eigen::Quaterniond r = cam_from_world.rotation;
    q[0] = r.x(), q[1] = r.y(), q[2] = r.z(), q[3] = r.w();
    for (int i = 0; i < 3; ++i) t[i] = cam_from_world.translation[i];
  }
  Rigid3d ToRigid() const {
    return Rigid3d(Eigen::Quaterniond(Eigen::Map<const Eigen::Quaterniond>(q)),
                   Eigen::Vector3d(Eigen::Map<const Eigen::Vector3d>(t)));
  }
};

Eigen::VectorXd EvaluateResidual(const ceres::CostFunction& cost,
                                 const std::vector<const double*>& params) {
  Eigen::VectorXd r(cost.num_residuals());
  EXPECT_TRUE(cost.Evaluate(params.data(), r.data(), nullptr));
  return r;
}

Rigid3d RandomPose(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
  return Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(1.5 * u(rng), axis)),
                 Eigen::Vector3d(u(rng), u(rng), u(rng)) * 5.0);
}

// A world point 3-30 m in front of the camera.
Eigen::Vector3d RandomPointInFront(const Rigid3d& cam_from_world, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0), depth(3.0, 30.0);
  const double z = depth(rng);
  return cam_from_world.Inverse() * Eigen::Vector3d(0.5 * z * u(rng), 0.3 * z * u(rng), z);
}

Eigen::Vector3d StereoPixel(const PinholeStereoIntrinsics& k, const Eigen::Vector3d& p) {
  const double u = k.fx * p.x() / p.z() + k.cx;
  return {u, k.fy * p.y() / p.z() + k.cy, u - k.bf / p.z()};
}

// --- zero at the truth ---

TEST(CostFunctions, ZeroAtTruth) {
  std::mt19937 rng(1);
  const PinholeStereoIntrinsics k = SimpleIntrinsics();
  const Rigid3d pose = RandomPose(rng);
  const Eigen::Vector3d x = RandomPointInFront(pose, rng);
  const Eigen::Vector3d pixel = StereoPixel(k, pose * x);
  const PoseParams params(pose);
  const std::vector<const double*> full = {params.q, params.t, x.data()};
  const std::vector<const double*> pose_only = {params.q, params.t};

  std::unique_ptr<ceres::CostFunction> stereo(StereoReprojectionError::Create(k, pixel, 2.0));
  std::unique_ptr<ceres::CostFunction> mono(MonoReprojectionError::Create(k, pixel.head<2>(), 2.0));
  const StereoPoseOnlyError stereo_pose(k, pixel, x, 2.0);
  const MonoPoseOnlyError mono_pose(k, pixel.head<2>(), x, 2.0);
  EXPECT_LT(EvaluateResidual(*stereo, full).norm(), 1e-9);
  EXPECT_LT(EvaluateResidual(*mono, full).norm(), 1e-9);
  EXPECT_LT(EvaluateResidual(StereoReprojectionAnalytic(k, pixel, 2.0), full).norm(), 1e-9);
  EXPECT_LT(EvaluateResidual(MonoReprojectionAnalytic(k, pixel.head<2>(), 2.0), full).norm(), 1e-9);
  EXPECT_LT(EvaluateResidual(MonoReprojectionPadded(k, pixel.head<2>(), 2.0), full).norm(), 1e-9);
  EXPECT_LT(EvaluateResidual(stereo_pose, pose_only).norm(), 1e-9);
  EXPECT_LT(EvaluateResidual(mono_pose, pose_only).norm(), 1e-9);

  const Plane plane = Plane::FromPointAndNormal(x, Eigen::Vector3d(1, 2, 3));
  std::unique_ptr<ceres::CostFunction> to_plane(PointToPlaneError::Create(plane, 0.05));
  EXPECT_LT(EvaluateResidual(*to_plane, {x.data()}).norm(), 1e-9);
}

// --- one hand-computed value ---

TEST(CostFunctions, HandComputedValues) {
  // Camera at identity rotation, t = (0.5, 0, 0): the point (1, 2, 10) is (1.5, 2, 10) in the
  // camera: u_L = 500 * 0.15 + 320 = 395, v = 500 * 0.2 + 240 = 340, u_R = 395 - 250 / 10 = 370.
  const PinholeStereoIntrinsics k = SimpleIntrinsics();
  const PoseParams params(Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.5, 0, 0)));
  const Eigen::Vector3d x(1, 2, 10);
  const Eigen::Vector3d observed(397, 337, 371);  // off by (+2, -3, +1) px
  const double information = 4.0;                 // sigma = 0.5 px, sqrt(info) = 2
  std::unique_ptr<ceres::CostFunction> stereo(
      StereoReprojectionError::Create(k, observed, information));
  std::unique_ptr<ceres::CostFunction> mono(
      MonoReprojectionError::Create(k, observed.head<2>(), information));
  const StereoPoseOnlyError stereo_pose(k, observed, x, information);
  const MonoPoseOnlyError mono_pose(k, observed.head<2>(), x, information);
  const Eigen::Vector3d expected(4, -6, 2);
  EXPECT_LT((EvaluateResidual(*stereo, {params.q, params.t, x.data()}) - expected).norm(), 1e-9);
  EXPECT_LT((EvaluateResidual(*mono, {params.q, params.t, x.data()}) - expected.head<2>()).norm(),
            1e-9);
  EXPECT_LT((EvaluateResidual(stereo_pose, {params.q, params.t}) - expected).norm(), 1e-9);
  const std::vector<const double*> full = {params.q, params.t, x.data()};
  EXPECT_LT(
      (EvaluateResidual(StereoReprojectionAnalytic(k, observed, information), full) - expected)
          .norm(),
      1e-9);
  EXPECT_LT((EvaluateResidual(MonoReprojectionAnalytic(k, observed.head<2>(), information), full) -
             expected.head<2>())
                .norm(),
            1e-9);
  // The padded mono residual has the same two rows and an identically zero third.
  EXPECT_LT((EvaluateResidual(MonoReprojectionPadded(k, observed.head<2>(), information), full) -
             Eigen::Vector3d(4, -6, 0))
                .norm(),
            1e-9);
  EXPECT_LT((EvaluateResidual(mono_pose, {params.q, params.t}) - expected.head<2>()).norm(), 1e-9);

  // Plane 2 z - 4 = 0 (normalized to z = 2), point at z = 2.5, sigma 0.1 m: r = 0.5 / 0.1 = 5.
  std::unique_ptr<ceres::CostFunction> to_plane(
      PointToPlaneError::Create(Plane(Eigen::Vector3d(0, 0, 2), -4), 0.1));
  const Eigen::Vector3d on_side(3, 4, 2.5);
  EXPECT_NEAR(EvaluateResidual(*to_plane, {on_side.data()})[0], 5.0, 1e-12);
}

// The corrected plane (the map's error as a nuisance): with c = 0 the plain point-to-plane
// residual; the offset adds to the distance; a tilt pivots the plane about its anchor.
TEST(CostFunctions, CorrectedPlaneHandComputedValues) {
  const Plane ground(Eigen::Vector3d(0, 0, 1), 0);  // z = 0
  // The anchor is projected onto the plane: (0, 0, 5) acts as the origin.
  std::unique_ptr<ceres::CostFunction> cost(
      PointToCorrectedPlaneError::Create(ground, Eigen::Vector3d(0, 0, 5), 0.1));
  const Eigen::Vector3d above(3, 4, 0.25);
  const Eigen::Vector3d none(0, 0, 0), offset(0.05, 0, 0);
  EXPECT_NEAR(EvaluateResidual(*cost, {above.data(), none.data()})[0], 2.5, 1e-12);
  EXPECT_NEAR(EvaluateResidual(*cost, {above.data(), offset.data()})[0], 3.0, 1e-12);
  // Basis of z = 0: u = n x X = (0, 1, 0), v = n x u = (-1, 0, 0). A tilt t along v turns the
  // normal to (-t, 0, 1) / sqrt(1 + t^2): the point (1, 0, 0) is then -t / sqrt(1 + t^2) off,
  // and (0, 1, 0) (on the pivot axis) stays on the plane.
  const double t = 0.01;
  const Eigen::Vector3d tilt(0, 0, t), on_x(1, 0, 0), on_y(0, 1, 0);
  EXPECT_NEAR(EvaluateResidual(*cost, {on_x.data(), tilt.data()})[0],
              -t / std::sqrt(1 + t * t) / 0.1, 1e-12);
  EXPECT_NEAR(EvaluateResidual(*cost, {on_y.data(), tilt.data()})[0], 0.0, 1e-12);

  std::unique_ptr<ceres::CostFunction> prior(PlaneCorrectionPrior::Create(0.05, 0.01));
  const Eigen::Vector3d c(0.1, 0.01, -0.02);
  EXPECT_LT((EvaluateResidual(*prior, {c.data()}) - Eigen::Vector3d(2, 1, -2)).norm(), 1e-12);
  std::unique_ptr<ceres::CostFunction> offset_only(PlaneCorrectionPrior::Create(0.05, 0));
  EXPECT_LT((EvaluateResidual(*offset_only, {c.data()}) - Eigen::Vector3d(2, 0, 0)).norm(), 1e-12);
}

TEST(CostFunctions, PointBehindCameraFails) {
  const PinholeStereoIntrinsics k = SimpleIntrinsics();
  const PoseParams params(Rigid3d::Identity());
  const Eigen::Vector3d x(1, 2, -10);
  const StereoPoseOnlyError cost(k, Eigen::Vector3d(0, 0, 0), x, 1.0);
  const double* p[2] = {params.q, params.t};
  double r[3];
  EXPECT_FALSE(cost.Evaluate(p, r, nullptr));
  std::unique_ptr<ceres::CostFunction> stereo(
      StereoReprojectionError::Create(k, Eigen::Vector3d(0, 0, 0), 1.0));
  const double* full[3] = {params.q, params.t, x.data()};
  EXPECT_FALSE(stereo->Evaluate(full, r, nullptr));
}

// --- Jacobians against numeric differentiation ---

void ExpectGradientsMatch(const ceres::CostFunction& cost,
                          const std::vector<const ceres::Manifold*>& manifolds,
                          const std::vector<const double*>& params) {
  ceres::NumericDiffOptions numeric_options;
  // Ridders starts at 1 % of each parameter; keep the probes small so points stay in front.
  numeric_options.ridders_relative_initial_step_size = 1e-4;
  const ceres::GradientChecker checker(&cost, &manifolds, numeric_options);
  ceres::GradientChecker::ProbeResults results;
  EXPECT_TRUE(checker.Probe(params.data(), 1e-6, &results)) << results.error_log;
}

TEST(CostFunctions, JacobiansMatchNumericDifferentiation) {
  std::mt19937 rng(2);
  const PinholeStereoIntrinsics k = SimpleIntrinsics();
  const ceres::EigenQuaternionManifold quaternion;
  std::normal_distribution<double> noise(0.0, 3.0);
  for (int trial = 0; trial < 20; ++trial) {
    const Rigid3d pose = RandomPose(rng);
    const Eigen::Vector3d x = RandomPointInFront(pose, rng);
    const Eigen::Vector3d observed =
        StereoPixel(k, pose * x) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    const PoseParams params(pose);
    std::unique_ptr<ceres::CostFunction> stereo(StereoReprojectionError::Create(k, observed, 0.7));
    std::unique_ptr<ceres::CostFunction> mono(
        MonoReprojectionError::Create(k, observed.head<2>(), 0.7));
    ExpectGradientsMatch(*stereo, {&quaternion, nullptr, nullptr}, {params.q, params.t, x.data()});
    ExpectGradientsMatch(*mono, {&quaternion, nullptr, nullptr}, {params.q, params.t, x.data()});
    const StereoPoseOnlyError stereo_pose(k, observed, x, 0.7);
    const MonoPoseOnlyError mono_pose(k, observed.head<2>(), x, 0.7);
    ExpectGradientsMatch(stereo_pose, {&quaternion, nullptr}, {params.q, params.t});
    ExpectGradientsMatch(mono_pose, {&quaternion, nullptr}, {params.q, params.t});

    const StereoReprojectionAnalytic stereo_analytic(k, observed, 0.7);
    const MonoReprojectionAnalytic mono_analytic(k, observed.head<2>(), 0.7);
    const MonoReprojectionPadded mono_padded(k, observed.head<2>(), 0.7);
    for (const ceres::CostFunction* cost :
         std::vector<const ceres::CostFunction*>{&stereo_analytic, &mono_analytic, &mono_padded}) {
      ExpectGradientsMatch(*cost, {&quaternion, nullptr, nullptr}, {params.q, params.t, x.data()});
    }

    // The analytic Jacobians equal the automatic ones in ambient coordinates.
    double r_auto[3], r_analytic[3], jq_auto[12], jt_auto[9], jx_auto[9], jq[12], jt[9];
    double* j_auto[3] = {jq_auto, jt_auto, jx_auto};
    double* j_analytic[2] = {jq, jt};
    const double* full[3] = {params.q, params.t, x.data()};
    const double* pose_only[2] = {params.q, params.t};
    ASSERT_TRUE(stereo->Evaluate(full, r_auto, j_auto));
    ASSERT_TRUE(stereo_pose.Evaluate(pose_only, r_analytic, j_analytic));
    for (int i = 0; i < 12; ++i) EXPECT_NEAR(jq[i], jq_auto[i], 1e-9 * (1 + std::abs(jq[i])));
    for (int i = 0; i < 9; ++i) EXPECT_NEAR(jt[i], jt_auto[i], 1e-9 * (1 + std::abs(jt[i])));
    double jx[9];
    double* j_full[3] = {jq, jt, jx};
    ASSERT_TRUE(stereo_analytic.Evaluate(full, r_analytic, j_full));
    for (int i = 0; i < 12; ++i) EXPECT_NEAR(jq[i], jq_auto[i], 1e-9 * (1 + std::abs(jq[i])));
    for (int i = 0; i < 9; ++i) EXPECT_NEAR(jt[i], jt_auto[i], 1e-9 * (1 + std::abs(jt[i])));
    for (int i = 0; i < 9; ++i) EXPECT_NEAR(jx[i], jx_auto[i], 1e-9 * (1 + std::abs(jx[i])));

    const Plane plane(Eigen::Vector3d(noise(rng), noise(rng), noise(rng)), noise(rng));
    std::unique_ptr<ceres::CostFunction> to_plane(PointToPlaneError::Create(plane, 0.05));
    ExpectGradientsMatch(*to_plane, {nullptr}, {x.data()});
    const Eigen::Vector3d anchor(noise(rng), noise(rng), noise(rng));
    const Eigen::Vector3d correction(0.05 * noise(rng), 0.01 * noise(rng), 0.01 * noise(rng));
    std::unique_ptr<ceres::CostFunction> to_corrected(
        PointToCorrectedPlaneError::Create(plane, anchor, 0.05));
    ExpectGradientsMatch(*to_corrected, {nullptr, nullptr}, {x.data(), correction.data()});

    // The padded variants: row 0 equals the 1-row residual and Jacobian, rows 1-2 are zero.
    const PointToPlanePadded to_plane_padded(plane, 0.05);
    ExpectGradientsMatch(to_plane_padded, {nullptr}, {x.data()});
    std::unique_ptr<ceres::CostFunction> to_corrected_padded(
        PointToCorrectedPlanePadded::Create(plane, anchor, 0.05));
    ExpectGradientsMatch(*to_corrected_padded, {nullptr, nullptr}, {x.data(), correction.data()});
    const double* plane_params[1] = {x.data()};
    const double* corrected_params[2] = {x.data(), correction.data()};
    double r1[1], j1x[3], j1c[3], r3[3], j3x[9], j3c[9];
    double* j1[2] = {j1x, j1c};
    double* j3[2] = {j3x, j3c};
    struct Case {
      const ceres::CostFunction* unpadded;
      const ceres::CostFunction* padded;
      const double* const* params;
      int blocks;
    };
    for (const Case& c :
         {Case{to_plane.get(), &to_plane_padded, plane_params, 1},
          Case{to_corrected.get(), to_corrected_padded.get(), corrected_params, 2}}) {
      ASSERT_TRUE(c.unpadded->Evaluate(c.params, r1, j1));
      ASSERT_TRUE(c.padded->Evaluate(c.params, r3, j3));
      EXPECT_NEAR(r3[0], r1[0], 1e-12 * (1 + std::abs(r1[0])));
      EXPECT_EQ(r3[1], 0.0);
      EXPECT_EQ(r3[2], 0.0);
      for (int b = 0; b < c.blocks; ++b) {
        for (int col = 0; col < 3; ++col) {
          EXPECT_NEAR(j3[b][col], j1[b][col], 1e-12 * (1 + std::abs(j1[b][col])));
          EXPECT_EQ(j3[b][3 + col], 0.0);
          EXPECT_EQ(j3[b][6 + col], 0.0);
        }
      }
    }
  }
}

// --- tiny solves ---

// Recovers a perturbed pose from 30 fixed points with the given residual factory.
template <typename MakeCost>
double RecoveredPoseErrorM(MakeCost make_cost, bool points_as_blocks) {
  std::mt19937 rng(3);
  const PinholeStereoIntrinsics k = SimpleIntrinsics();
  const Rigid3d truth = RandomPose(rng);
  PoseParams params(test::Perturb(truth, 0.05, 0.3, rng));
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 30; ++i) points.push_back(RandomPointInFront(truth, rng));
  ceres::Problem problem;
  problem.AddParameterBlock(params.q, 4, new ceres::EigenQuaternionManifold);
  for (Eigen::Vector3d& x : points) {
    ceres::CostFunction* cost = make_cost(k, StereoPixel(k, truth * x), x);
    if (points_as_blocks) {
      problem.AddResidualBlock(cost, nullptr, params.q, params.t, x.data());
      problem.SetParameterBlockConstant(x.data());
    } else {
      problem.AddResidualBlock(cost, nullptr, params.q, params.t);
    }
  }
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = 50;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  EXPECT_TRUE(summary.IsSolutionUsable());
  const Rigid3d estimate = params.ToRigid();
  EXPECT_LT(RotationAngle(estimate.rotation, truth.rotation), 1e-6);
  return (estimate.translation - truth.translation).norm();
}

TEST(CostFunctions, TinySolvesRecoverPose) {
  using K = PinholeStereoIntrinsics;
  EXPECT_LT(RecoveredPoseErrorM(
                [](const K& k, const Eigen::Vector3d& px, const Eigen::Vector3d&) {
                  return StereoReprojectionError::Create(k, px, 1.0);
                },
                true),
            1e-6);
  EXPECT_LT(RecoveredPoseErrorM(
                [](const K& k, const Eigen::Vector3d& px, const Eigen::Vector3d&) {
                  return MonoReprojectionError::Create(k, px.head<2>(), 1.0);
                },
                true),
            1e-6);
  EXPECT_LT(RecoveredPoseErrorM(
                [](const K& k, const Eigen::Vector3d& px, const Eigen::Vector3d& x) {
                  return new StereoPoseOnlyError(k, px, x, 1.0);
                },
                false),
            1e-6);
  EXPECT_LT(RecoveredPoseErrorM(
                [](const K& k, const Eigen::Vector3d& px, const Eigen::Vector3d&) {
                  return new StereoReprojectionAnalytic(k, px, 1.0);
                },
                true),
            1e-6);
  EXPECT_LT(RecoveredPoseErrorM(
                [](const K& k, const Eigen::Vector3d& px, const Eigen::Vector3d&) {
                  return new MonoReprojectionPadded(k, px.head<2>(), 1.0);
                },
                true),
            1e-6);
  EXPECT_LT(RecoveredPoseErrorM(
                [](const K& k, const Eigen::Vector3d& px, const Eigen::Vector3d& x) {
                  return new MonoPoseOnlyError(k, px.head<2>(), x, 1.0);
                },
                false),
            1e-6);
}

TEST(CostFunctions, TinySolveRecoversPointFromTwoViews) {
  // A perturbed point seen by two fixed stereo cameras 1 m apart converges to the truth.
  const PinholeStereoIntrinsics k = SimpleIntrinsics();
  const Eigen::Vector3d truth(0.5, -0.4, 8.0);
  Eigen::Vector3d x = truth + Eigen::Vector3d(0.3, 0.2, -0.8);
  std::vector<PoseParams> poses = {
      PoseParams(Rigid3d::Identity()),
      PoseParams(Rigid3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-1.0, 0.0, 0.0)))};
  ceres::Problem problem;
  for (PoseParams& pose : poses) {
    const Eigen::Vector3d pixel = StereoPixel(k, pose.ToRigid() * truth);
    problem.AddResidualBlock(new StereoReprojectionAnalytic(k, pixel, 1.0), nullptr, pose.q, pose.t,
                             x.data());
    problem.AddResidualBlock(MonoReprojectionError::Create(k, pixel.head<2>(), 1.0), nullptr,
                             pose.q, pose.t, x.data());
    problem.SetParameterBlockConstant(pose.q);
    problem.SetParameterBlockConstant(pose.t);
  }
  ceres::Solver::Options options;
  options.max_num_iterations = 50;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  EXPECT_TRUE(summary.IsSolutionUsable());
  EXPECT_LT((x - truth).norm(), 1e-8);
}

TEST(CostFunctions, TinySolveRecoversPointFromPlanes) {
  // Three non-parallel planes meet in one point; point-to-plane residuals alone recover it.
  const Eigen::Vector3d corner(1.0, -2.0, 7.0);
  const std::vector<Plane> planes = {
      Plane::FromPointAndNormal(corner, Eigen::Vector3d(1, 0, 0.2)),
      Plane::FromPointAndNormal(corner, Eigen::Vector3d(0, 1, 0)),
      Plane::FromPointAndNormal(corner, Eigen::Vector3d(0.3, 0.1, 1))};
  Eigen::Vector3d x = corner + Eigen::Vector3d(0.4, -0.3, 0.5);
  ceres::Problem problem;
  for (const Plane& plane : planes) {
    problem.AddResidualBlock(PointToPlaneError::Create(plane, 0.05), nullptr, x.data());
  }
  ceres::Solver::Options options;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
  EXPECT_TRUE(summary.IsSolutionUsable());
  EXPECT_LT((x - corner).norm(), 1e-7);
}

}  // namespace
}  // namespace planeloc
