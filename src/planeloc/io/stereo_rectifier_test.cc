#include "planeloc/io/stereo_rectifier.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

namespace planeloc {
namespace {

// A EuRoC-like raw rig (made up for this test): 752x480, radial-tangential distortion, the right
// camera 11 cm to the right and slightly rotated.
struct Rig {
  RawCamera left{(cv::Mat_<double>(3, 3) << 458.0, 0, 367.0, 0, 457.0, 248.0, 0, 0, 1),
                 (cv::Mat_<double>(1, 5) << -0.28, 0.074, 2e-4, 2e-5, 0.0)};
  RawCamera right{(cv::Mat_<double>(3, 3) << 457.5, 0, 380.0, 0, 456.0, 255.0, 0, 0, 1),
                  (cv::Mat_<double>(1, 4) << -0.283, 0.0745, -1e-4, -3.5e-5)};
  cv::Mat left_from_right = [] {
    cv::Mat rotation;
    cv::Rodrigues(cv::Vec3d(0.004, -0.012, 0.002), rotation);
    cv::Mat t = cv::Mat::eye(4, 4, CV_64F);
    rotation.copyTo(t(cv::Rect(0, 0, 3, 3)));
    t.at<double>(0, 3) = 0.110;
    t.at<double>(1, 3) = -0.0004;
    t.at<double>(2, 3) = 0.0008;
    return t;
  }();
  cv::Size size{752, 480};
};

// Raw pixels of a point given in the left camera frame.
void ProjectRaw(const Rig& rig, const cv::Point3d& point_in_left, cv::Point2d* left,
                cv::Point2d* right) {
  const cv::Mat r = rig.left_from_right(cv::Rect(0, 0, 3, 3)).t();  // right_from_left
  const cv::Mat t = -r * rig.left_from_right(cv::Rect(3, 0, 1, 3));
  std::vector<cv::Point2d> out;
  cv::projectPoints(std::vector<cv::Point3d>{point_in_left}, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                    rig.left.k, rig.left.d, out);
  *left = out.front();
  cv::Vec3d rvec;
  cv::Rodrigues(r, rvec);
  cv::projectPoints(std::vector<cv::Point3d>{point_in_left}, rvec,
                    cv::Vec3d(t.at<double>(0), t.at<double>(1), t.at<double>(2)), rig.right.k,
                    rig.right.d, out);
  *right = out.front();
}

TEST(StereoRectifierTest, RectifiedPairsHaveEqualRowsAndDisparityFxBOverZ) {
  const Rig rig;
  const StereoRectifier rectifier =
      StereoRectifier::FromExtrinsics(rig.left, rig.right, rig.left_from_right, rig.size);
  const StereoCamera& camera = rectifier.camera();
  EXPECT_NEAR(camera.baseline, cv::norm(rig.left_from_right(cv::Rect(3, 0, 1, 3))), 1e-9);
  EXPECT_EQ(camera.width, 752);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> xy(-1.5, 1.5), depth(2.0, 20.0);
  for (int i = 0; i < 50; ++i) {
    const cv::Point3d point(xy(rng), xy(rng), depth(rng));
    cv::Point2d raw_left, raw_right;
    ProjectRaw(rig, point, &raw_left, &raw_right);
    if (raw_left.x < 0 || raw_left.y < 0 || raw_left.x > 751 || raw_left.y > 479) continue;
    const cv::Point2d left = rectifier.RectifyLeftPixel(raw_left);
    const cv::Point2d right = rectifier.RectifyRightPixel(raw_right);
    EXPECT_NEAR(left.y, right.y, 1e-3) << i;
    // Depth in the rectified left frame: the rectification rotates the left camera by R1.
    EXPECT_GT(left.x - right.x, 0.0);
    const double z = camera.DepthFromDisparity(left.x - right.x);
    EXPECT_NEAR(z, point.z, 0.02 * point.z) << i;  // R1 tilts the optical axis by < 1 degree
  }
}

// The images are remapped in the right direction: a dot drawn at a raw pixel lands at the
// rectified pixel predicted for it.
TEST(StereoRectifierTest, RemapMovesADotToItsRectifiedPixel) {
  const Rig rig;
  const StereoRectifier rectifier =
      StereoRectifier::FromExtrinsics(rig.left, rig.right, rig.left_from_right, rig.size);
  StereoPair raw{cv::Mat::zeros(rig.size, CV_8UC1), cv::Mat::zeros(rig.size, CV_8UC1)};
  const cv::Point2d dot(600.0, 90.0);  // near a corner: strong distortion
  cv::circle(raw.left, cv::Point(600, 90), 3, cv::Scalar(255), cv::FILLED);
  const StereoPair rectified = rectifier.Rectify(raw);
  ASSERT_EQ(rectified.left.size(), rig.size);
  const cv::Moments m = cv::moments(rectified.left);
  ASSERT_GT(m.m00, 0.0);
  const cv::Point2d centroid(m.m10 / m.m00, m.m01 / m.m00);
  const cv::Point2d expected = rectifier.RectifyLeftPixel(dot);
  EXPECT_NEAR(centroid.x, expected.x, 0.5);
  EXPECT_NEAR(centroid.y, expected.y, 0.5);
  EXPECT_GT(cv::norm(expected - dot), 5.0);  // the test means something: the dot moved

  EXPECT_THROW(rectifier.Rectify({cv::Mat::zeros(10, 10, CV_8UC1), raw.right}),
               std::invalid_argument);
}

// ORB-SLAM2 style: the rectification (R, P) is given. With the R and P of stereoRectify the
// result equals FromExtrinsics.
TEST(StereoRectifierTest, GivenRectificationEqualsComputedOne) {
  const Rig rig;
  const cv::Mat r = rig.left_from_right(cv::Rect(0, 0, 3, 3)).t();
  const cv::Mat t = -r * rig.left_from_right(cv::Rect(3, 0, 1, 3));
  cv::Mat r1, r2, p1, p2, q;
  cv::stereoRectify(rig.left.k, rig.left.d, rig.right.k, rig.right.d, rig.size, r, t, r1, r2, p1,
                    p2, q, cv::CALIB_ZERO_DISPARITY, 0.0, rig.size);
  const StereoRectifier given =
      StereoRectifier::FromRectification(rig.left, r1, p1, rig.right, r2, p2, rig.size);
  const StereoRectifier computed =
      StereoRectifier::FromExtrinsics(rig.left, rig.right, rig.left_from_right, rig.size);
  EXPECT_DOUBLE_EQ(given.camera().fx, computed.camera().fx);
  EXPECT_DOUBLE_EQ(given.camera().baseline, computed.camera().baseline);
  cv::Mat image(rig.size, CV_8UC1);
  cv::randu(image, 0, 255);
  const StereoPair a = given.Rectify({image, image});
  const StereoPair b = computed.Rectify({image, image});
  EXPECT_EQ(cv::norm(a.left, b.left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.right, b.right, cv::NORM_INF), 0.0);

  EXPECT_THROW(StereoRectifier::FromRectification(rig.left, r1, p1(cv::Rect(0, 0, 3, 3)), rig.right,
                                                  r2, p2, rig.size),
               std::invalid_argument);
}

}  // namespace
}  // namespace planeloc
