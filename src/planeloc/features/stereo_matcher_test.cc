#include "planeloc/features/stereo_matcher.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "planeloc/features/test_images.h"
#include "planeloc/util/error.h"
#include "planeloc/util/test_data.h"

namespace planeloc {
namespace {

StereoCamera KittiLikeCamera() {
  StereoCamera camera;
  camera.fx = camera.fy = 718.856;
  camera.cx = 607.19;
  camera.cy = 185.22;
  camera.baseline = 0.537;
  camera.width = 1226;
  camera.height = 370;
  return camera;
}

double Median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

// Three fronto-parallel planes, one per horizontal band of rows, at known depths: the right
// image is the left one shifted by the band's disparity, R(u, v) = L(u + d(v), v).
struct PlanesScene {
  cv::Mat left, right;
  std::vector<double> band_disparity;
  int band_height = 0;
  double DisparityAt(double v) const {
    return band_disparity[std::min<int>(static_cast<int>(v) / band_height,
                                        static_cast<int>(band_disparity.size()) - 1)];
  }
};

PlanesScene MakePlanesScene(const StereoCamera& camera, const std::vector<double>& depths) {
  PlanesScene scene;
  scene.left = testing::RandomTexture(cv::Size(camera.width, camera.height), 11, 200.0, 128.0, 1.0);
  scene.band_height = camera.height / static_cast<int>(depths.size()) + 1;
  for (double depth : depths) scene.band_disparity.push_back(camera.BaselineTimesFx() / depth);
  cv::Mat map_x(scene.left.size(), CV_32F), map_y(scene.left.size(), CV_32F);
  for (int v = 0; v < map_x.rows; ++v) {
    for (int u = 0; u < map_x.cols; ++u) {
      map_x.at<float>(v, u) = static_cast<float>(u + scene.DisparityAt(v));
      map_y.at<float>(v, u) = static_cast<float>(v);
    }
  }
  cv::remap(scene.left, scene.right, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REFLECT_101);
  return scene;
}

TEST(StereoMatchOptions, CheckRejectsBadFields) {
  StereoMatchOptions options;
  EXPECT_NO_THROW(options.Check());
  options.min_depth = -1;
  EXPECT_THROW(options.Check(), OptionsError);
  options = StereoMatchOptions();
  options.sad_window_half_size = 0;
  EXPECT_THROW(options.Check(), OptionsError);
}

TEST(StereoMatcher, RecoversDisparityAndDepthOfPlanes) {
  const StereoCamera camera = KittiLikeCamera();
  const std::vector<double> depths = {6.0, 11.0, 19.0};  // disparities 64.3, 35.1, 20.3 px
  const PlanesScene scene = MakePlanesScene(camera, depths);
  const OrbExtractor extractor{OrbOptions()};
  const StereoFeatures features =
      ExtractStereoFeatures(scene.left, scene.right, camera, extractor, StereoMatchOptions());

  ASSERT_EQ(features.u_right.size(), features.left.keypoints.size());
  ASSERT_EQ(features.depth.size(), features.left.keypoints.size());
  EXPECT_GT(features.num_right_keypoints, 1500);
  EXPECT_GE(features.num_stereo_matches(), 800);
  std::vector<double> disparity_errors, depth_errors;
  int gross = 0;
  for (size_t i = 0; i < features.depth.size(); ++i) {
    if (features.depth[i] <= 0) continue;
    const cv::KeyPoint& kp = features.left.keypoints[i];
    // Stay clear of the band edges, where the SAD window straddles two planes.
    const double in_band = std::fmod(kp.pt.y, scene.band_height);
    if (in_band < 12 || in_band > scene.band_height - 12) continue;
    const double true_disparity = scene.DisparityAt(kp.pt.y);
    const double error = kp.pt.x - features.u_right[i] - true_disparity;
    disparity_errors.push_back(std::abs(error));
    depth_errors.push_back(std::abs(features.depth[i] - camera.BaselineTimesFx() / true_disparity) /
                           (camera.BaselineTimesFx() / true_disparity));
    if (std::abs(error) > 2.0) ++gross;
  }
  ASSERT_GE(disparity_errors.size(), 500u);
  EXPECT_LT(Median(disparity_errors), 0.2);
  EXPECT_LT(Median(depth_errors), 0.01);
  EXPECT_LT(gross, 0.02 * disparity_errors.size());
}

// Where the right image is corrupted by strong noise, descriptors may still match but the patch
// costs are far above the median: those matches must be rejected. (On the coarse levels the
// downsampling averages the noise away and matches there are legitimately kept.)
TEST(StereoMatcher, RejectsMatchesWithOutlyingPatchCost) {
  const StereoCamera camera = KittiLikeCamera();
  PlanesScene scene = MakePlanesScene(camera, {12.0});
  const cv::Rect noisy(0, 0, camera.width / 3, camera.height);
  cv::Mat noise(noisy.size(), CV_16S);
  cv::RNG(7).fill(noise, cv::RNG::NORMAL, 0, 30);
  cv::Mat patch;
  scene.right(noisy).convertTo(patch, CV_16S);
  patch += noise;
  patch.convertTo(scene.right(noisy), CV_8U);

  const OrbExtractor extractor{OrbOptions()};
  const StereoFeatures features =
      ExtractStereoFeatures(scene.left, scene.right, camera, extractor, StereoMatchOptions());
  int clean_matches = 0, clean_keypoints = 0, noisy_matches = 0, noisy_keypoints = 0;
  for (size_t i = 0; i < features.depth.size(); ++i) {
    const cv::KeyPoint& kp = features.left.keypoints[i];
    const double u_right_true = kp.pt.x - scene.DisparityAt(kp.pt.y);
    const bool in_noise = u_right_true < noisy.width - 10;
    const bool in_clean = u_right_true > noisy.width + 10;
    const bool matched = features.depth[i] > 0;
    if (in_noise && kp.octave <= 2) {
      ++noisy_keypoints;
      noisy_matches += matched;
    } else if (in_clean) {
      ++clean_keypoints;
      clean_matches += matched;
    }
  }
  ASSERT_GT(noisy_keypoints, 150);
  ASSERT_GT(clean_keypoints, 800);
  EXPECT_GT(clean_matches, 0.6 * clean_keypoints);
  EXPECT_LT(noisy_matches, 0.05 * noisy_keypoints);
}

TEST(StereoMatcher, RespectsMinimumDepth) {
  const StereoCamera camera = KittiLikeCamera();
  const PlanesScene scene = MakePlanesScene(camera, {6.0, 19.0});
  const OrbExtractor extractor{OrbOptions()};
  StereoMatchOptions options;
  options.min_depth = 10.0;  // the 6 m plane is closer: none of its points may match
  const StereoFeatures features =
      ExtractStereoFeatures(scene.left, scene.right, camera, extractor, options);
  ASSERT_GT(features.num_stereo_matches(), 300);
  for (float depth : features.depth) {
    if (depth > 0) {
      EXPECT_GE(depth, 10.0f);
    }
  }
}

TEST(StereoMatcher, NoFeaturesNoMatches) {
  const StereoCamera camera = KittiLikeCamera();
  const cv::Mat flat(camera.height, camera.width, CV_8U, cv::Scalar(100));
  const cv::Mat textured = testing::RandomTexture(flat.size(), 12);
  const OrbExtractor extractor{OrbOptions()};
  const StereoFeatures none =
      ExtractStereoFeatures(textured, flat, camera, extractor, StereoMatchOptions());
  EXPECT_GT(none.left.keypoints.size(), 1000u);
  EXPECT_EQ(none.num_right_keypoints, 0);
  EXPECT_EQ(none.num_stereo_matches(), 0);
  ASSERT_EQ(none.u_right.size(), none.left.keypoints.size());
  for (float u : none.u_right) EXPECT_EQ(u, -1.0f);
}

TEST(StereoMatcher, RealKittiPair) {
  PLANELOC_SHARED_DATA_OR_SKIP(dir, "kitti-raw-2011_09_26_drive_0001");
  const cv::Mat left =
      cv::imread((dir / "image_00/data/0000000000.png").string(), cv::IMREAD_GRAYSCALE);
  const cv::Mat right =
      cv::imread((dir / "image_01/data/0000000000.png").string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(left.empty());
  ASSERT_FALSE(right.empty());
  // P_rect_00 / P_rect_01 of the drive's calib_cam_to_cam.txt.
  StereoCamera camera;
  camera.fx = camera.fy = 721.5377;
  camera.cx = 609.5593;
  camera.cy = 172.854;
  camera.baseline = 387.5744 / 721.5377;
  camera.width = left.cols;
  camera.height = left.rows;

  const OrbExtractor extractor{OrbOptions()};
  StereoFeatures features;
  features.left = extractor.Extract(left);
  const ImageFeatures right_features = extractor.Extract(right);
  MatchStereo(right_features, camera, extractor, StereoMatchOptions(), features);

  EXPECT_GE(features.left.keypoints.size(), 1500u);
  EXPECT_GE(features.num_stereo_matches(), 500);
  std::vector<double> row_offsets, depths;
  for (size_t i = 0; i < features.depth.size(); ++i) {
    if (features.depth[i] <= 0) continue;
    ASSERT_GE(features.right_index[i], 0);
    row_offsets.push_back(std::abs(features.left.keypoints[i].pt.y -
                                   right_features.keypoints[features.right_index[i]].pt.y));
    depths.push_back(features.depth[i]);
  }
  ASSERT_FALSE(row_offsets.empty());
  EXPECT_LT(Median(row_offsets), 1.0);
  // A street scene: most stereo points are a few to a few tens of metres away.
  EXPECT_GT(Median(depths), 3.0);
  EXPECT_LT(Median(depths), 40.0);
}

}  // namespace
}  // namespace planeloc
