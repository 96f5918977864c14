#include "planeloc/optim/window_ba.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "planeloc/optim/test_scene.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// Median error of the points (optionally only those on a plane): far monocular points have
// metre-level depth uncertainty, which would dominate a mean.
double MedianPointError(const test::WindowScene& s, const std::map<int, Eigen::Vector3d>& points,
                        bool planar_only) {
  std::vector<double> errors;
  for (const WindowPoint& p : s.problem.points) {
    if (planar_only && !p.plane_id) continue;
    errors.push_back((points.at(p.id) - s.point_true[p.id]).norm());
  }
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  return errors[errors.size() / 2];
}

double MedianInitialPointError(const test::WindowScene& s, bool planar_only) {
  std::map<int, Eigen::Vector3d> points;
  for (const WindowPoint& p : s.problem.points) points[p.id] = p.point_in_world;
  return MedianPointError(s, points, planar_only);
}

// Mean camera-centre error of the free keyframes.
double MeanPoseError(const test::WindowScene& s, const std::map<int, Rigid3d>& poses) {
  double sum = 0;
  for (const auto& [id, pose] : poses) {
    sum += (pose.Inverse().translation - s.cam_from_world_true[id].Inverse().translation).norm();
  }
  return sum / poses.size();
}

double MeanInitialPoseError(const test::WindowScene& s) {
  std::map<int, Rigid3d> poses;
  for (const WindowKeyframe& kf : s.problem.keyframes) {
    if (!kf.fixed) poses[kf.id] = kf.cam_from_world;
  }
  return MeanPoseError(s, poses);
}

// Distance of the last keyframe's centre from keyframe 0's, over the true one: the window scale.
double WindowScale(const test::WindowScene& s, const std::map<int, Rigid3d>& poses) {
  const int last = static_cast<int>(s.cam_from_world_true.size()) - 1;
  const Eigen::Vector3d c0 = s.cam_from_world_true[0].Inverse().translation;
  return (poses.at(last).Inverse().translation - c0).norm() /
         (s.cam_from_world_true[last].Inverse().translation - c0).norm();
}

TEST(SolveWindowBa, ReducesPoseAndPointError) {
  const test::WindowScene s = test::MakeWindowScene({});
  ASSERT_GT(s.problem.observations.size(), 1500u);
  const WindowBaResult r = SolveWindowBa(s.camera, s.problem, {});
  ASSERT_TRUE(r.usable);
  EXPECT_EQ(r.num_plane_residuals, 0);                                 // lambda = 1: visual only
  EXPECT_EQ(r.cam_from_world.size(), s.problem.keyframes.size() - 1);  // keyframe 0 fixed
  EXPECT_EQ(r.point_in_world.size(), s.problem.points.size());
  const double pose_before = MeanInitialPoseError(s),
               pose_after = MeanPoseError(s, r.cam_from_world);
  EXPECT_LT(pose_after, 0.3 * pose_before) << pose_before << " -> " << pose_after;
  EXPECT_LT(pose_after, 0.03);
  const double point_before = MedianInitialPointError(s, false);
  const double point_after = MedianPointError(s, r.point_in_world, false);
  EXPECT_LT(point_after, point_before) << point_before << " -> " << point_after;
  EXPECT_LT(r.final_cost, r.initial_cost);
  int inliers = 0;
  for (bool b : r.observation_inlier) inliers += b ? 1 : 0;
  EXPECT_GT(inliers, 0.9 * r.observation_inlier.size());
}

TEST(SolveWindowBa, FlagsGrossOutliers) {
  test::WindowScene s = test::MakeWindowScene({.point_sigma = 0.1, .seed = 2});
  std::map<int, int> num_observations;
  for (const WindowObservation& o : s.problem.observations) ++num_observations[o.point_id];
  // Corrupt one observation of every third point seen at least 3 times (a point seen once or
  // twice can move to fit a corrupted measurement, so only redundant ones are detectable).
  std::set<int> corrupted_points;
  std::vector<size_t> corrupted;
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> angle(0.0, 2 * M_PI);
  for (size_t i = 0; i < s.problem.observations.size(); ++i) {
    WindowObservation& o = s.problem.observations[i];
    if (o.point_id % 3 != 0 || num_observations[o.point_id] < 3) continue;
    if (!corrupted_points.insert(o.point_id).second) continue;
    const double a = angle(rng);
    o.u_left += 40 * std::cos(a);
    o.v += 40 * std::sin(a);
    if (o.u_right >= 0) o.u_right += 40 * std::cos(a);
    corrupted.push_back(i);
  }
  ASSERT_GT(corrupted.size(), 100u);
  const WindowBaResult r = SolveWindowBa(s.camera, s.problem, {});
  ASSERT_TRUE(r.usable);
  for (size_t i : corrupted) EXPECT_FALSE(r.observation_inlier[i]) << i;
  EXPECT_LT(MeanPoseError(s, r.cam_from_world), 0.05);
}

TEST(SolveWindowBa, PlaneConstraintsImprovePlanarPoints) {
  const test::WindowScene s = test::MakeWindowScene({.seed = 3});
  const WindowBaResult visual = SolveWindowBa(s.camera, s.problem, {});
  WindowBaOptions with_planes;
  with_planes.lambda = 0.5;
  const WindowBaResult planar = SolveWindowBa(s.camera, s.problem, with_planes);
  ASSERT_TRUE(visual.usable);
  ASSERT_TRUE(planar.usable);
  // Every planar point that is observed (a few of the 450 never enter an image).
  EXPECT_GT(planar.num_plane_residuals, 400);
  EXPECT_LE(planar.num_plane_residuals, 450);
  const double e_visual = MedianPointError(s, visual.point_in_world, true);
  const double e_planar = MedianPointError(s, planar.point_in_world, true);
  EXPECT_LT(e_planar, 0.7 * e_visual) << e_visual << " -> " << e_planar;
}

// Monocular-only window: the scale is a gauge freedom of the reprojection error, so a drifted
// scale stays drifted with lambda = 1; the metric LiDAR planes pull it back.
TEST(SolveWindowBa, PlanesRecoverScaleDriftMonocular) {
  const test::WindowScene s =
      test::MakeWindowScene({.pose_trans_sigma = 0.02, .scale = 1.1, .mono_only = true, .seed = 4});
  const WindowBaResult visual = SolveWindowBa(s.camera, s.problem, {});
  WindowBaOptions with_planes;
  with_planes.lambda = 0.5;
  const WindowBaResult planar = SolveWindowBa(s.camera, s.problem, with_planes);
  ASSERT_TRUE(visual.usable);
  ASSERT_TRUE(planar.usable);
  const double scale_visual = WindowScale(s, visual.cam_from_world);
  const double scale_planar = WindowScale(s, planar.cam_from_world);
  EXPECT_GT(std::abs(scale_visual - 1.0), 0.05) << scale_visual;
  EXPECT_LT(std::abs(scale_planar - 1.0), 0.01) << scale_planar;
}

// Stereo window with 10 % scale drift: stereo alone observes scale only weakly at these depths;
// the planes must give a measurably better window scale and pose error.
TEST(SolveWindowBa, PlanesReduceScaleDriftStereo) {
  const test::WindowScene s =
      test::MakeWindowScene({.pose_trans_sigma = 0.02, .scale = 1.1, .seed = 5});
  const WindowBaResult visual = SolveWindowBa(s.camera, s.problem, {});
  WindowBaOptions with_planes;
  with_planes.lambda = 0.5;
  const WindowBaResult planar = SolveWindowBa(s.camera, s.problem, with_planes);
  ASSERT_TRUE(visual.usable);
  ASSERT_TRUE(planar.usable);
  const double scale_err_visual = std::abs(WindowScale(s, visual.cam_from_world) - 1.0);
  const double scale_err_planar = std::abs(WindowScale(s, planar.cam_from_world) - 1.0);
  EXPECT_LT(scale_err_planar, 0.5 * scale_err_visual)
      << scale_err_visual << " -> " << scale_err_planar;
  EXPECT_LT(MeanPoseError(s, planar.cam_from_world), MeanPoseError(s, visual.cam_from_world));
}

// Points associated with the wrong plane (metres away from it) lose their plane term after
// round 1, so a wrong association does not drag the window.
TEST(SolveWindowBa, WrongPlaneAssociationsAreDropped) {
  test::WindowScene s = test::MakeWindowScene({.seed = 9});
  int reassigned = 0;
  for (WindowPoint& p : s.problem.points) {
    if (p.plane_id == 1 && p.id % 4 == 0) {  // left-wall points claimed by the right wall
      p.plane_id = 2;
      ++reassigned;
    }
  }
  ASSERT_GT(reassigned, 20);
  const WindowBaResult visual = SolveWindowBa(s.camera, s.problem, {});
  WindowBaOptions with_planes;
  with_planes.lambda = 0.5;
  const WindowBaResult planar = SolveWindowBa(s.camera, s.problem, with_planes);
  ASSERT_TRUE(planar.usable);
  // Second method: the same window with the wrong associations removed beforehand.
  test::WindowScene oracle = test::MakeWindowScene({.seed = 9});
  for (WindowPoint& p : oracle.problem.points) {
    if (p.plane_id == 1 && p.id % 4 == 0) p.plane_id.reset();
  }
  const WindowBaResult dropped = SolveWindowBa(oracle.camera, oracle.problem, with_planes);
  ASSERT_TRUE(dropped.usable);
  // Every wrong association lost its residual, and no right one did.
  EXPECT_EQ(planar.num_plane_residuals, dropped.num_plane_residuals);
  // Round 1 still felt the wrong planes (Huber-bounded): the solutions differ by millimetres.
  // Measured on seeds 9 / 12 / 13 (2026-12-02): largest keyframe-centre difference 2.5 / 3.0 /
  // 8.1 mm; mean pose error 0.0046 / 0.0087 / 0.0090 m, visual only 0.0149 / 0.0067 / 0.0097 m.
  for (const auto& [id, pose] : planar.cam_from_world) {
    EXPECT_LT(
        (pose.Inverse().translation - dropped.cam_from_world.at(id).Inverse().translation).norm(),
        0.016)
        << id;
  }
  const double e_planar = MeanPoseError(s, planar.cam_from_world);
  EXPECT_LT(e_planar, 0.015);  // 1.7x the worst of the three seeds
  EXPECT_LT(e_planar, MeanPoseError(s, visual.cam_from_world));  // 0.31x on this seed
}

// Only lambda / (1 - lambda) matters: lambda = 0.8 with sigma_plane equals lambda = 0.5 with
// sigma_plane * sqrt(0.8 / 0.2) (the Huber threshold in metres unchanged) up to solver tolerance.
TEST(SolveWindowBa, LambdaActsAsPlaneSigmaRatio) {
  const test::WindowScene s = test::MakeWindowScene({.seed = 10});
  WindowBaOptions a;
  a.lambda = 0.8;
  a.plane_sigma = 0.05;
  WindowBaOptions b;
  b.lambda = 0.5;
  b.plane_sigma = 0.05 * std::sqrt(0.8 / 0.2);
  const WindowBaResult ra = SolveWindowBa(s.camera, s.problem, a);
  const WindowBaResult rb = SolveWindowBa(s.camera, s.problem, b);
  ASSERT_TRUE(ra.usable);
  ASSERT_TRUE(rb.usable);
  for (const auto& [id, pose] : ra.cam_from_world) {
    EXPECT_LT((pose.translation - rb.cam_from_world.at(id).translation).norm(), 1e-3) << id;
  }
  // The costs differ by the overall factor lambda_a / lambda_b.
  EXPECT_NEAR(ra.final_cost / rb.final_cost, 0.8 / 0.5, 0.01 * 0.8 / 0.5);
}

// Per-point sigma (issue 10): every point given sigma 0.1 m solves the same problem as the
// global plane_sigma 0.1 m (Huber 0.4 m there, so that both kernels sit at 4 whitened units),
// and differs from the global 0.05 m the points would get without their own.
TEST(SolveWindowBa, PerPointPlaneSigmaWhitensThePlaneTerm) {
  test::WindowScene s = test::MakeWindowScene({.seed = 10});
  WindowBaOptions global;
  global.lambda = 0.5;
  global.plane_sigma = 0.1;
  global.plane_huber = 0.4;
  const WindowBaResult reference = SolveWindowBa(s.camera, s.problem, global);
  WindowBaOptions options;
  options.lambda = 0.5;  // plane_sigma 0.05, plane_huber 0.2: Huber at 4 sigma
  const WindowBaResult without = SolveWindowBa(s.camera, s.problem, options);
  for (WindowPoint& p : s.problem.points) p.plane_sigma = 0.1;
  const WindowBaResult per_point = SolveWindowBa(s.camera, s.problem, options);
  ASSERT_TRUE(reference.usable && without.usable && per_point.usable);
  double differs = 0;
  for (const auto& [id, x] : reference.point_in_world) {
    EXPECT_LT((per_point.point_in_world.at(id) - x).norm(), 1e-9) << id;
    differs = std::max(differs, (without.point_in_world.at(id) - x).norm());
  }
  EXPECT_GT(differs, 1e-4);
  EXPECT_NEAR(per_point.final_cost, reference.final_cost, 1e-9 * reference.final_cost);
}

// Gauge-free error: the mean over keyframe pairs (0, k) of the translation error of
// cam_k_from_cam_0, which a rigid motion of the whole window does not change.
double MeanRelativePoseError(const test::WindowScene& s, const std::map<int, Rigid3d>& poses) {
  double sum = 0;
  int n = 0;
  for (const auto& [id, pose] : poses) {
    if (id == 0) continue;
    const Rigid3d relative = pose * poses.at(0).Inverse();
    const Rigid3d truth = s.cam_from_world_true[id] * s.cam_from_world_true[0].Inverse();
    sum += (relative.translation - truth.translation).norm();
    ++n;
  }
  return sum / n;
}

// Metres: sigma of a point's stereo position along `normal`, from the keyframe that sees it
// closest (depth sigma z^2 / (fx b) * sqrt(2) px for 1 px noise on both images, along the ray),
// combined with a 5 cm map sigma: what an uncertainty-aware association hands the BA.
double StereoSigmaAlong(const test::WindowScene& s, int point_id, const Eigen::Vector3d& normal) {
  double best = 1e9;
  for (const Rigid3d& cam_from_world : s.cam_from_world_true) {
    const Eigen::Vector3d x = cam_from_world * s.point_true[point_id];
    if (x.z() < 2.0 || x.z() > 40 * s.camera.baseline) continue;
    const double sigma_depth = x.z() * x.z() / (s.camera.fx * s.camera.baseline) * std::sqrt(2.0);
    const Eigen::Vector3d ray_in_world = cam_from_world.rotation.conjugate() * x.normalized();
    const double along = sigma_depth / x.normalized().z() * std::abs(normal.dot(ray_in_world));
    best = std::min(best, along);
  }
  return std::sqrt(best * best + 0.05 * 0.05);
}

// A near miss (issue 13): a quarter of the left wall's points associated with a parallel plane
// 0.3 m in front of it (a parked truck, scaffolding, a map 0.3 m off). The BA cannot reject it
// (0.3 m is within plane_outlier_distance, and all but 2-4 of the ~37 keep their residual):
// at these depths stereo barely sees 0.3 m along the wall (the points slide 0.2-1 m along their
// rays and stay chi2 inliers), so rejecting near misses is the association gate's job. What the
// BA does is bound the damage by each point's own sigma (the stereo uncertainty along the normal
// the association hands over): the pose error must be lower than with the global 5 cm sigma and
// stay bounded. Measured (2026-12-02), seeds 9 / 12 / 13, mean free-keyframe error: global sigma
// 0.0143 / 0.0231 / 0.0282 m, per-point sigma 0.0052 / 0.0133 / 0.0186 m (visual only 0.0149 /
// 0.0067 / 0.0097 m; with the right associations 0.0106 / 0.0066 / 0.0066 m).
TEST(SolveWindowBa, NearMissWrongPlaneIsBoundedByThePointSigma) {
  for (const unsigned seed : {9u, 12u, 13u}) {
    test::WindowScene s = test::MakeWindowScene({.seed = seed});
    s.problem.planes.push_back({3, Plane(Eigen::Vector3d(1, 0, 0), 6.0 - 0.3)});  // x = -5.7
    int near_miss = 0;
    for (WindowPoint& p : s.problem.points) {
      if (p.plane_id == 1 && p.id % 4 == 0) {
        p.plane_id = 3;
        ++near_miss;
      }
    }
    ASSERT_GT(near_miss, 20);
    WindowBaOptions options;
    options.lambda = 0.5;
    const WindowBaResult global = SolveWindowBa(s.camera, s.problem, options);
    for (WindowPoint& p : s.problem.points) {
      if (p.plane_id) p.plane_sigma = StereoSigmaAlong(s, p.id, Eigen::Vector3d(1, 0, 0));
    }
    const WindowBaResult per_point = SolveWindowBa(s.camera, s.problem, options);
    ASSERT_TRUE(global.usable && per_point.usable);
    const double e_global = MeanPoseError(s, global.cam_from_world);
    const double e_point = MeanPoseError(s, per_point.cam_from_world);
    EXPECT_LT(e_point, e_global) << "seed " << seed;  // measured ratios 0.36 / 0.58 / 0.66
    EXPECT_LT(e_point, 0.035) << "seed " << seed;     // 1.9x the worst measured (0.0186 m)
  }
}

// A map plane that is wrong by a few centimetres (issue 10, the noisy map): the road of the map
// 8 cm below the true road. Held fixed, its ~150 points (sigma 2 cm each, as a clean-looking
// map plane gets) pull the free keyframes down by most of those 8 cm; as a random effect
// (WindowPlane::offset_sigma 5 cm) the window estimates the road's correction and the prior is
// the only tie, so the keyframes stay near the visual solution. Measured (2026-12-02), seeds
// 21 / 22 / 23 (build/bin/planeloc_optim_test --gtest_filter='*PlaneCorrection*'), mean
// free-keyframe error: visual only 0.0059 / 0.0081 / 0.0136 m, fixed plane 0.0165 / 0.0284 /
// 0.0166 m, corrected 0.0062 / 0.0072 / 0.0124 m; estimated offset -0.0772 / -0.0784 /
// -0.0801 m (the map is off by +0.08 m along its normal).
TEST(SolveWindowBa, PlaneCorrectionAbsorbsAWrongPlaneOffset) {
  for (const unsigned seed : {21u, 22u, 23u}) {
    test::WindowScene s = test::MakeWindowScene({.seed = seed});
    for (WindowPlane& plane : s.problem.planes) {
      if (plane.id == 0) plane.plane_in_world = Plane(Eigen::Vector3d(0, -1, 0), 1.6 + 0.08);
    }
    for (WindowPoint& p : s.problem.points) {
      if (p.plane_id) p.plane_sigma = 0.02;
    }
    WindowBaOptions options;
    options.lambda = 0.5;
    const WindowBaResult visual = SolveWindowBa(s.camera, s.problem, {});
    const WindowBaResult fixed = SolveWindowBa(s.camera, s.problem, options);
    for (WindowPlane& plane : s.problem.planes) {
      plane.offset_sigma = 0.05;
      plane.tilt_sigma = 0.5 * M_PI / 180;
      plane.anchor = Eigen::Vector3d(0, plane.id == 0 ? 1.68 : 0, 8);
    }
    const WindowBaResult corrected = SolveWindowBa(s.camera, s.problem, options);
    ASSERT_TRUE(visual.usable && fixed.usable && corrected.usable);
    const double e_visual = MeanPoseError(s, visual.cam_from_world);
    const double e_fixed = MeanPoseError(s, fixed.cam_from_world);
    const double e_corrected = MeanPoseError(s, corrected.cam_from_world);
    ASSERT_EQ(corrected.plane_correction.count(0), 1u);
    const Eigen::Vector3d road = corrected.plane_correction.at(0);
    EXPECT_TRUE(fixed.plane_correction.empty());
    // The scene feels the wrong plane when it is held fixed (measured 1.22-3.5x visual) ...
    EXPECT_GT(e_fixed, 1.15 * e_visual) << "seed " << seed;
    // ... and not when it is corrected (measured 0.89-1.05x visual; fixed / corrected 0.25-0.75).
    EXPECT_LT(e_corrected, 1.5 * e_visual) << "seed " << seed;
    EXPECT_LT(e_corrected, 0.9 * e_fixed) << "seed " << seed;
    EXPECT_NEAR(road[0], -0.08, 0.015) << "seed " << seed;                  // measured within 3 mm
    EXPECT_LT(road.tail<2>().norm(), 0.5 * M_PI / 180) << "seed " << seed;  // measured <= 0.07 deg
  }
}

// With every keyframe free the gauge (a rigid motion of the whole window) is unobserved, but
// Levenberg-Marquardt's damping keeps the system solvable: the gauge-free geometry (keyframe k
// relative to keyframe 0) is recovered as well as with keyframe 0 fixed, and the window does
// not wander off. Measured on seeds 6 / 14 / 15 (2026-12-02): relative error 0.190 / 0.141 /
// 0.194 m before, 0.0095 / 0.0111 / 0.0056 m after (same as with keyframe 0 fixed to 1e-5 m);
// keyframe 0 moved by 0.026 / 0.070 / 0.020 m.
TEST(SolveWindowBa, AllKeyframesFreeIsStillUsable) {
  test::WindowScene s = test::MakeWindowScene({.seed = 6});
  std::map<int, Rigid3d> initial;
  for (const WindowKeyframe& kf : s.problem.keyframes) initial[kf.id] = kf.cam_from_world;
  const WindowBaResult anchored = SolveWindowBa(s.camera, s.problem, {});
  std::map<int, Rigid3d> anchored_all = anchored.cam_from_world;
  anchored_all[0] = initial.at(0);
  for (WindowKeyframe& kf : s.problem.keyframes) kf.fixed = false;
  const WindowBaResult r = SolveWindowBa(s.camera, s.problem, {});
  ASSERT_TRUE(r.usable);
  ASSERT_EQ(r.cam_from_world.size(), s.problem.keyframes.size());
  const double before = MeanRelativePoseError(s, initial);
  const double after = MeanRelativePoseError(s, r.cam_from_world);
  EXPECT_GT(before, 0.1);
  EXPECT_LT(after, 0.02);  // 0.0095 measured
  EXPECT_NEAR(after, MeanRelativePoseError(s, anchored_all), 1e-3);
  EXPECT_LT((r.cam_from_world.at(0).translation - initial.at(0).translation).norm(), 0.15);
}

TEST(SolveWindowBa, SparseAndDenseSchurAgree) {
  const test::WindowScene s = test::MakeWindowScene({.seed = 8});
  WindowBaOptions sparse;
  sparse.dense_schur_max_keyframes = 0;  // force SPARSE_SCHUR
  const WindowBaResult a = SolveWindowBa(s.camera, s.problem, {});
  const WindowBaResult b = SolveWindowBa(s.camera, s.problem, sparse);
  ASSERT_TRUE(a.usable);
  ASSERT_TRUE(b.usable);
  for (const auto& [id, pose] : a.cam_from_world) {
    EXPECT_LT((pose.translation - b.cam_from_world.at(id).translation).norm(), 1e-6);
  }
  EXPECT_NEAR(a.final_cost, b.final_cost, 1e-6 * a.final_cost);
}

TEST(SolveWindowBa, TwoThreadsMatchOneThread) {
  const test::WindowScene s = test::MakeWindowScene({.seed = 11});
  WindowBaOptions two;
  two.num_threads = 2;
  const WindowBaResult a = SolveWindowBa(s.camera, s.problem, {});
  const WindowBaResult b = SolveWindowBa(s.camera, s.problem, two);
  ASSERT_TRUE(b.usable);
  for (const auto& [id, pose] : a.cam_from_world) {
    EXPECT_LT((pose.translation - b.cam_from_world.at(id).translation).norm(), 1e-6);
  }
}

TEST(SolveWindowBa, DeterministicBitForBit) {
  const test::WindowScene s = test::MakeWindowScene({.seed = 7});
  WindowBaOptions options;
  options.lambda = 0.7;
  const WindowBaResult a = SolveWindowBa(s.camera, s.problem, options);
  const WindowBaResult b = SolveWindowBa(s.camera, s.problem, options);
  for (const auto& [id, pose] : a.cam_from_world) {
    EXPECT_EQ(pose.translation, b.cam_from_world.at(id).translation);
    EXPECT_EQ(pose.rotation.coeffs(), b.cam_from_world.at(id).rotation.coeffs());
  }
  EXPECT_EQ(a.point_in_world, b.point_in_world);
  EXPECT_EQ(a.observation_inlier, b.observation_inlier);
}

TEST(SolveWindowBa, RejectsBadInput) {
  test::WindowScene s =
      test::MakeWindowScene({.keyframes = 3, .points_per_plane = 10, .off_plane_points = 10});
  WindowBaOptions options;
  options.lambda = 0.0;
  EXPECT_THROW(SolveWindowBa(s.camera, s.problem, options), OptionsError);
  options.lambda = 1.5;
  EXPECT_THROW(options.Check(), OptionsError);
  options = {};
  options.plane_sigma = 0;
  EXPECT_THROW(options.Check(), OptionsError);
  s.problem.observations[0].point_id = 99999;
  EXPECT_THROW(SolveWindowBa(s.camera, s.problem, {}), std::invalid_argument);
}

TEST(SolveWindowBa, EmptyProblemIsNotUsableAndKeepsInput) {
  WindowProblem problem;
  problem.keyframes.push_back({0, Rigid3d::Identity(), true});
  problem.keyframes.push_back({1, Rigid3d::Identity(), false});
  problem.points.push_back({0, Eigen::Vector3d(1, 2, 3), std::nullopt});
  const WindowBaResult r = SolveWindowBa(test::KittiLikeCamera(), problem, {});
  EXPECT_FALSE(r.usable);
  EXPECT_EQ(r.point_in_world.at(0), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(r.cam_from_world.size(), 1u);
}

}  // namespace
}  // namespace planeloc
