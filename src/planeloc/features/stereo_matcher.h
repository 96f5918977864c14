// Stereo matching of ORB features along rectified rows (ORB-SLAM2's ComputeStereoMatches done
// as a small function): for each left keypoint, candidate right keypoints on nearby rows (band
// grows with the pyramid scale) within the disparity range [0, fx*b/min_depth]; best Hamming
// distance; SAD patch refinement at the keypoint's level with a parabola fit for sub-pixel
// disparity; rejection of matches whose SAD exceeds 1.5 x 1.4 x median (distance statistics).
#pragma once

#include <vector>

#include "planeloc/features/dense_stereo.h"
#include "planeloc/features/orb_extractor.h"
#include "planeloc/geometry/camera.h"

namespace planeloc {

struct StereoMatchOptions {
  int max_descriptor_distance = 75;  // (ORB-SLAM2: (TH_HIGH + TH_LOW) / 2)
  int sad_window_half_size = 5;      // pixels at the keypoint's level
  int sad_search_half_range = 5;     // pixels at the keypoint's level
  double min_depth = 0.0;            // metres; disparities beyond fx*b/min_depth are rejected
                                     // (0 = up to fx, i.e. depth >= baseline)
  void Check() const;
};

// Features of a rectified stereo pair: the left image's features with their stereo match.
struct StereoFeatures {
  ImageFeatures left;
  std::vector<float> u_right;    // level-0 x of the match in the right image, -1 if none
  std::vector<float> depth;      // metres along the left camera z, -1 if none
  std::vector<int> right_index;  // matched right keypoint (descriptor match), -1 if none
  int num_right_keypoints = 0;
  // Dense disparity of the pair, when the run asks for one (the depth prior); empty otherwise.
  DenseDisparity dense;
  int num_stereo_matches() const;
};

// Matches left features against right features. `left` and `right` must come from the same
// extractor (same pyramid levels).
void MatchStereo(const ImageFeatures& right, const StereoCamera& camera,
                 const OrbExtractor& extractor, const StereoMatchOptions& options,
                 StereoFeatures& features);

// Extracts both images (concurrently) and matches them.
StereoFeatures ExtractStereoFeatures(const cv::Mat& left, const cv::Mat& right,
                                     const StereoCamera& camera, const OrbExtractor& extractor,
                                     const StereoMatchOptions& options);

}  // namespace planeloc
