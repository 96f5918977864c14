// ORB features spread over the image, ORB-SLAM2 style: an 8-level image pyramid (scale 1.2),
// per level FAST on a cell grid with an adaptive threshold (initial, then minimum where a cell
// finds nothing), quadtree distribution to the per-level budget, intensity-centroid orientation
// and rotated BRIEF (256 bit) descriptors. Plain cv::ORB clusters features on textured spots,
// which starves tracking in uniform regions: that is why this is not cv::ORB::detect.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <vector>

namespace planeloc {

struct OrbOptions {
  int num_features = 2000;    // per image, summed over levels
  double scale_factor = 1.2;  // between consecutive pyramid levels
  int num_levels = 8;
  int initial_fast_threshold = 20;  // grey levels
  int min_fast_threshold = 7;       // used in cells where the initial one finds nothing
  // Throws planeloc::OptionsError naming the field.
  void Check() const;
};

// Keypoints and descriptors of one image. Keypoint coordinates are level-0 pixels; `octave` is
// the pyramid level; `size` the patch diameter at that level; `angle` in degrees [0, 360);
// `response` the FAST score. Keypoints are ordered by level; descriptor row i belongs to
// keypoint i.
struct ImageFeatures {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;           // N x 32, CV_8U
  std::vector<cv::Mat> pyramid;  // the grey image pyramid, level 0 = a copy of the input image
};

class OrbExtractor {
 public:
  explicit OrbExtractor(const OrbOptions& options);

  // Thread-safe (const, no shared mutable state): left and right images may be extracted
  // concurrently. `grey` must be CV_8UC1 (else std::invalid_argument). Deterministic: the
  // result does not depend on thread scheduling.
  ImageFeatures Extract(const cv::Mat& grey) const;

  const OrbOptions& options() const { return options_; }
  int num_levels() const { return options_.num_levels; }
  // scale_factor^level, and its square: the variance multiplier of a measurement at `level`.
  double ScaleFactor(int level) const { return scale_factors_.at(level); }
  double LevelSigma2(int level) const { return level_sigma2_.at(level); }
  double InverseLevelSigma2(int level) const { return 1.0 / level_sigma2_.at(level); }
  // Feature budget of each level (sums to num_features).
  const std::vector<int>& FeaturesPerLevel() const { return features_per_level_; }
  // The grey pyramid: level l is the input resized by 1/ScaleFactor(l) (sizes rounded).
  std::vector<cv::Mat> BuildPyramid(const cv::Mat& grey) const;

 private:
  struct LevelFeatures {
    std::vector<cv::KeyPoint> keypoints;  // level-0 coordinates
    cv::Mat descriptors;
  };
  LevelFeatures ExtractLevel(const cv::Mat& image, int level) const;

  OrbOptions options_;
  std::vector<double> scale_factors_;
  std::vector<double> level_sigma2_;
  std::vector<int> features_per_level_;
};

// Hamming distance between two 32-byte ORB descriptors (rows of a CV_8U matrix).
int DescriptorDistance(const cv::Mat& a, const cv::Mat& b);
// Same on raw 32-byte descriptors.
int DescriptorDistance(const uint8_t* a, const uint8_t* b);

}  // namespace planeloc
