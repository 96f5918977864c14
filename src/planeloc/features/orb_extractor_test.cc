#include "planeloc/features/orb_extractor.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <future>
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "planeloc/features/test_images.h"
#include "planeloc/util/error.h"
#include "planeloc/util/test_data.h"

namespace planeloc {
namespace {

const cv::Size kKittiLikeSize(1226, 370);

// Fraction of the cells of a cols x rows grid over the image that hold at least one keypoint.
double GridCoverage(const std::vector<cv::KeyPoint>& keypoints, cv::Size image, int cols,
                    int rows) {
  std::vector<int> counts(cols * rows, 0);
  for (const cv::KeyPoint& kp : keypoints) {
    const int c = std::clamp(static_cast<int>(kp.pt.x * cols / image.width), 0, cols - 1);
    const int r = std::clamp(static_cast<int>(kp.pt.y * rows / image.height), 0, rows - 1);
    ++counts[r * cols + c];
  }
  return static_cast<double>(
             std::count_if(counts.begin(), counts.end(), [](int n) { return n > 0; })) /
         counts.size();
}

TEST(OrbOptions, CheckRejectsBadFields) {
  OrbOptions options;
  EXPECT_NO_THROW(options.Check());
  options.scale_factor = 1.0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = OrbOptions();
  options.min_fast_threshold = 30;  // above the initial threshold
  EXPECT_THROW(options.Check(), OptionsError);
  options = OrbOptions();
  options.num_features = 0;
  EXPECT_THROW(OrbExtractor{options}, OptionsError);
}

TEST(OrbExtractor, LevelBudgetIsAGeometricSeriesSummingToTheTotal) {
  const OrbExtractor extractor{OrbOptions()};
  const std::vector<int>& budget = extractor.FeaturesPerLevel();
  ASSERT_EQ(budget.size(), 8u);
  int sum = 0;
  for (int n : budget) sum += n;
  EXPECT_EQ(sum, 2000);
  for (size_t level = 1; level + 1 < budget.size(); ++level) {
    EXPECT_NEAR(static_cast<double>(budget[level - 1]) / budget[level], 1.2, 0.02);
  }
  EXPECT_NEAR(extractor.ScaleFactor(3), std::pow(1.2, 3), 1e-12);
  EXPECT_NEAR(extractor.LevelSigma2(2), std::pow(1.2, 4), 1e-12);
}

TEST(OrbExtractor, FillsTheBudgetOverAllLevels) {
  const cv::Mat image = testing::RandomTexture(kKittiLikeSize, 1);
  const OrbExtractor extractor{OrbOptions()};
  const ImageFeatures features = extractor.Extract(image);
  EXPECT_GE(features.keypoints.size(), 1800u);  // >= 90 % of 2000
  EXPECT_LE(features.keypoints.size(), 2100u);
  ASSERT_EQ(features.descriptors.rows, static_cast<int>(features.keypoints.size()));
  EXPECT_EQ(features.descriptors.cols, 32);
  EXPECT_EQ(features.descriptors.type(), CV_8U);
  ASSERT_EQ(features.pyramid.size(), 8u);
  EXPECT_EQ(cv::norm(features.pyramid[0], image, cv::NORM_INF), 0.0);
  EXPECT_NE(features.pyramid[0].data, image.data);  // a copy, not a view of the caller's buffer
  EXPECT_EQ(features.pyramid[1].cols, 1022);        // round(1226 / 1.2)

  std::vector<int> per_level(8, 0);
  for (const cv::KeyPoint& kp : features.keypoints) {
    ASSERT_GE(kp.octave, 0);
    ASSERT_LT(kp.octave, 8);
    ++per_level[kp.octave];
    EXPECT_NEAR(kp.size, 31.0 * extractor.ScaleFactor(kp.octave), 1e-3);
    EXPECT_GE(kp.angle, 0.0f);
    EXPECT_LT(kp.angle, 360.0f);
    // Level-0 coordinates, away from the border by the BRIEF patch of the keypoint's level.
    const double border = 18.0 * extractor.ScaleFactor(kp.octave);
    EXPECT_GE(kp.pt.x, border);
    EXPECT_GE(kp.pt.y, border);
    EXPECT_LE(kp.pt.x, image.cols - border);
    EXPECT_LE(kp.pt.y, image.rows - border);
  }
  for (int level = 0; level < 8; ++level) {
    EXPECT_GE(per_level[level], 0.8 * extractor.FeaturesPerLevel()[level]) << "level " << level;
  }
  EXPECT_GE(GridCoverage(features.keypoints, image.size(), 8, 4), 0.99);
}

// One half strongly textured, the other with contrast below cv::ORB's FAST threshold: the cell
// grid with the fallback threshold keeps features on both halves, cv::ORB does not.
TEST(OrbExtractor, SpreadsFeaturesWhereCvOrbClusters) {
  cv::Mat image = testing::RandomTexture(kKittiLikeSize, 2, 220.0);
  const cv::Mat weak = testing::RandomTexture(kKittiLikeSize, 3, 24.0);
  const cv::Rect right_half(kKittiLikeSize.width / 2, 0, kKittiLikeSize.width / 2,
                            kKittiLikeSize.height);
  weak(right_half).copyTo(image(right_half));

  const ImageFeatures ours = OrbExtractor{OrbOptions()}.Extract(image);
  std::vector<cv::KeyPoint> cv_orb;
  cv::ORB::create(2000)->detect(image, cv_orb);

  const double ours_coverage = GridCoverage(ours.keypoints, image.size(), 8, 4);
  const double cv_coverage = GridCoverage(cv_orb, image.size(), 8, 4);
  EXPECT_GE(ours_coverage, 0.8);
  EXPECT_LT(cv_coverage, 0.6);
  const auto in_weak_half = [&](const std::vector<cv::KeyPoint>& kps) {
    return std::count_if(kps.begin(), kps.end(),
                         [&](const cv::KeyPoint& kp) { return kp.pt.x >= right_half.x; });
  };
  EXPECT_GE(in_weak_half(ours.keypoints), 400);
  EXPECT_LT(in_weak_half(cv_orb), 0.1 * cv_orb.size());
}

TEST(OrbExtractor, IsDeterministicAndThreadSafe) {
  const cv::Mat image = testing::RandomTexture(kKittiLikeSize, 4);
  const OrbExtractor extractor{OrbOptions()};
  const ImageFeatures reference = extractor.Extract(image);
  auto a = std::async(std::launch::async, [&] { return extractor.Extract(image); });
  auto b = std::async(std::launch::async, [&] { return extractor.Extract(image); });
  for (const ImageFeatures& other : {a.get(), b.get()}) {
    ASSERT_EQ(other.keypoints.size(), reference.keypoints.size());
    for (size_t i = 0; i < reference.keypoints.size(); ++i) {
      EXPECT_EQ(other.keypoints[i].pt, reference.keypoints[i].pt);
      EXPECT_EQ(other.keypoints[i].angle, reference.keypoints[i].angle);
      EXPECT_EQ(other.keypoints[i].octave, reference.keypoints[i].octave);
    }
    EXPECT_EQ(cv::norm(other.descriptors, reference.descriptors, cv::NORM_HAMMING), 0.0);
  }
}

// A 90-degree rotation of a square image permutes its pixels: the same corners must come back,
// with angles rotated by 90 degrees and (nearly) the same descriptors.
TEST(OrbExtractor, DescriptorsAreRotationInvariant) {
  const cv::Mat image = testing::RandomTexture(cv::Size(480, 480), 5);
  cv::Mat rotated;
  cv::rotate(image, rotated, cv::ROTATE_90_CLOCKWISE);  // (x, y) -> (H - 1 - y, x)
  const OrbExtractor extractor{OrbOptions()};
  const ImageFeatures original = extractor.Extract(image);
  const ImageFeatures turned = extractor.Extract(rotated);

  int compared = 0, descriptor_matches = 0, angle_ok = 0;
  for (size_t i = 0; i < original.keypoints.size(); ++i) {
    const cv::KeyPoint& kp = original.keypoints[i];
    if (kp.octave != 0) continue;  // level 0 is an exact permutation; coarser levels resample
    const cv::Point2f expected(image.rows - 1 - kp.pt.y, kp.pt.x);
    for (size_t j = 0; j < turned.keypoints.size(); ++j) {
      const cv::KeyPoint& other = turned.keypoints[j];
      if (other.octave != 0 || cv::norm(other.pt - expected) > 0.5) continue;
      ++compared;
      const float turn = std::fmod(other.angle - kp.angle + 720.0f, 360.0f);
      if (std::abs(turn - 90.0f) < 2.0f) ++angle_ok;
      if (DescriptorDistance(original.descriptors.row(i), turned.descriptors.row(j)) <= 20) {
        ++descriptor_matches;
      }
    }
  }
  ASSERT_GE(compared, 100);
  EXPECT_GE(angle_ok, 0.95 * compared);
  EXPECT_GE(descriptor_matches, 0.8 * compared);
}

// A 30-degree rotation resamples the image: brute-force descriptor matches must still mostly agree
// with the rotation (an unrotated BRIEF loses most of them at this angle).
TEST(OrbExtractor, MatchesAcrossAnArbitraryRotation) {
  const cv::Mat image = testing::RandomTexture(cv::Size(480, 480), 8, 200.0, 128.0, 0.7);
  const cv::Point2f centre(239.5f, 239.5f);
  const cv::Mat rotation = cv::getRotationMatrix2D(centre, 30.0, 1.0);
  cv::Mat rotated;
  cv::warpAffine(image, rotated, rotation, image.size(), cv::INTER_LINEAR, cv::BORDER_REFLECT_101);
  const OrbExtractor extractor{OrbOptions()};
  const ImageFeatures original = extractor.Extract(image);
  const ImageFeatures turned = extractor.Extract(rotated);
  std::vector<cv::DMatch> matches;
  cv::BFMatcher(cv::NORM_HAMMING, true).match(original.descriptors, turned.descriptors, matches);
  int consistent = 0, considered = 0;
  for (const cv::DMatch& m : matches) {
    const cv::Point2f p = original.keypoints[m.queryIdx].pt;
    if (cv::norm(p - centre) > 200) continue;  // corners of the original leave the image
    ++considered;
    const cv::Point2f expected(
        static_cast<float>(rotation.at<double>(0, 0) * p.x + rotation.at<double>(0, 1) * p.y +
                           rotation.at<double>(0, 2)),
        static_cast<float>(rotation.at<double>(1, 0) * p.x + rotation.at<double>(1, 1) * p.y +
                           rotation.at<double>(1, 2)));
    if (cv::norm(turned.keypoints[m.trainIdx].pt - expected) < 3.0) ++consistent;
  }
  ASSERT_GT(considered, 500);
  EXPECT_GT(consistent, 0.5 * considered);
}

TEST(OrbExtractor, RejectsNonGreyImages) {
  const OrbExtractor extractor{OrbOptions()};
  EXPECT_THROW(extractor.Extract(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(extractor.Extract(cv::Mat(100, 100, CV_8UC3)), std::invalid_argument);
}

TEST(OrbExtractor, HandlesSmallAndFlatImages) {
  const OrbExtractor extractor{OrbOptions()};
  // Coarse levels of a small image are smaller than the border: they simply yield nothing.
  const ImageFeatures small = extractor.Extract(testing::RandomTexture(cv::Size(120, 90), 6));
  EXPECT_GT(small.keypoints.size(), 50u);
  EXPECT_EQ(small.descriptors.rows, static_cast<int>(small.keypoints.size()));
  EXPECT_EQ(small.pyramid.size(), 8u);
  EXPECT_TRUE(extractor.Extract(cv::Mat(20, 20, CV_8U, cv::Scalar(0))).keypoints.empty());
  const ImageFeatures flat = extractor.Extract(cv::Mat(370, 1226, CV_8U, cv::Scalar(128)));
  EXPECT_TRUE(flat.keypoints.empty());
  EXPECT_EQ(flat.descriptors.rows, 0);
}

TEST(DescriptorDistance, CountsDifferingBits) {
  cv::Mat a = cv::Mat::zeros(1, 32, CV_8U), b = cv::Mat::zeros(1, 32, CV_8U);
  EXPECT_EQ(DescriptorDistance(a, b), 0);
  b.at<uchar>(0, 0) = 0xFF;
  b.at<uchar>(0, 31) = 0x01;
  EXPECT_EQ(DescriptorDistance(a, b), 9);
  EXPECT_EQ(DescriptorDistance(a, b), cv::norm(a, b, cv::NORM_HAMMING));
}

TEST(OrbExtractor, RealKittiImage) {
  PLANELOC_SHARED_DATA_OR_SKIP(path,
                               "kitti-raw-2011_09_26_drive_0001/image_00/data/0000000000.png");
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(image.empty());
  const ImageFeatures features = OrbExtractor{OrbOptions()}.Extract(image);
  EXPECT_GE(features.keypoints.size(), 1500u);
  EXPECT_GE(GridCoverage(features.keypoints, image.size(), 8, 4), 0.8);
}

}  // namespace
}  // namespace planeloc
