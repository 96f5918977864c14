#include "planeloc/features/stereo_matcher.h"

#include <tbb/task_group.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <utility>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

void Require(bool condition, const std::string& what) {
  if (!condition) throw OptionsError("StereoMatchOptions: " + what);
}

// Right keypoint indices by level-0 image row. A keypoint is listed on every row within
// +-2 * scale of its own (its position is only known to about a pixel of its level), so a left
// keypoint looks up candidates on its own row only.
std::vector<std::vector<int>> RowIndex(const std::vector<cv::KeyPoint>& right, int num_rows,
                                       const OrbExtractor& extractor) {
  std::vector<std::vector<int>> rows(num_rows);
  for (int i = 0; i < static_cast<int>(right.size()); ++i) {
    const float y = right[i].pt.y;
    const float r = 2.0f * static_cast<float>(extractor.ScaleFactor(right[i].octave));
    const int min_row = std::max(0, static_cast<int>(std::floor(y - r)));
    const int max_row = std::min(num_rows - 1, static_cast<int>(std::ceil(y + r)));
    for (int row = min_row; row <= max_row; ++row) rows[row].push_back(i);
  }
  return rows;
}

// Left patch of the SAD search, relative to its centre pixel (robust to a brightness offset
// between the cameras, as ORB-SLAM2), precomputed once per keypoint. Rows are padded with zeros
// to kStride values so that they can be processed 8 lanes at a time.
struct CenteredPatch {
  static constexpr int kStride = 32;
  alignas(16) std::array<int16_t, 31 * kStride> values{};
  int half_size = 0;
};

void FillCenteredPatch(const cv::Mat& image, int x, int y, int w, CenteredPatch& patch) {
  patch.half_size = w;
  const int centre = image.at<uchar>(y, x);
  for (int dy = -w; dy <= w; ++dy) {
    const uchar* row = image.ptr<uchar>(y + dy) + x - w;
    int16_t* out = patch.values.data() + (dy + w) * CenteredPatch::kStride;
    for (int i = 0; i < 2 * w + 1; ++i) out[i] = static_cast<int16_t>(row[i] - centre);
  }
}

// Sum of absolute differences between the centred left patch and the right patch centred at
// (x, y), itself taken relative to its centre pixel.
int CenteredSad(const CenteredPatch& left, const cv::Mat& right, int x, int y) {
  const int w = left.half_size, side = 2 * w + 1;
  const int right_centre = right.at<uchar>(y, x);
  int sad = 0;
  for (int dy = -w; dy <= w; ++dy) {
    const uchar* r = right.ptr<uchar>(y + dy) + x - w;
    const int16_t* l = left.values.data() + (dy + w) * CenteredPatch::kStride;
    for (int i = 0; i < side; ++i) sad += std::abs(l[i] + right_centre - r[i]);
  }
  return sad;
}

// Number of right-image bytes past x + w that the vectorized SAD reads.
int SadOverread(int w) { return 8 * ((2 * w + 8) / 8) - (2 * w + 1); }

#if defined(__SSE2__)
// The same sum, 8 pixels at a time (the SAD is ~70 % of the matching time when scalar). Reads
// SadOverread(w) bytes beyond the window on each row; the caller checks they are in the image.
int CenteredSadSse2(const CenteredPatch& left, const cv::Mat& right, int x, int y) {
  const int w = left.half_size, side = 2 * w + 1, chunks = (side + 7) / 8;
  const __m128i zero = _mm_setzero_si128();
  const __m128i right_centre = _mm_set1_epi16(static_cast<int16_t>(right.at<uchar>(y, x)));
  alignas(16) int16_t mask_values[4][8];
  for (int c = 0; c < chunks; ++c) {
    for (int lane = 0; lane < 8; ++lane) mask_values[c][lane] = (8 * c + lane < side) ? 1 : 0;
  }
  __m128i sum = zero;
  for (int dy = -w; dy <= w; ++dy) {
    const uchar* r = right.ptr<uchar>(y + dy) + x - w;
    const int16_t* l = left.values.data() + (dy + w) * CenteredPatch::kStride;
    for (int c = 0; c < chunks; ++c) {
      const __m128i r16 =
          _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(r + 8 * c)), zero);
      const __m128i l16 = _mm_load_si128(reinterpret_cast<const __m128i*>(l + 8 * c));
      const __m128i d = _mm_sub_epi16(_mm_add_epi16(l16, right_centre), r16);
      const __m128i abs_d = _mm_max_epi16(d, _mm_sub_epi16(zero, d));
      const __m128i mask = _mm_load_si128(reinterpret_cast<const __m128i*>(mask_values[c]));
      sum = _mm_add_epi32(sum, _mm_madd_epi16(abs_d, mask));
    }
  }
  sum = _mm_add_epi32(sum, _mm_shuffle_epi32(sum, _MM_SHUFFLE(1, 0, 3, 2)));
  sum = _mm_add_epi32(sum, _mm_shuffle_epi32(sum, _MM_SHUFFLE(2, 3, 0, 1)));
  return _mm_cvtsi128_si32(sum);
}
#endif

// Best right keypoint for left keypoint `kp` by Hamming distance among row candidates whose
// level is within one of kp's and whose x lies in [min_u, max_u]; -1 if none is close enough.
int BestDescriptorMatch(const cv::KeyPoint& kp, const uint8_t* descriptor,
                        const std::vector<int>& candidates, const ImageFeatures& right, float min_u,
                        float max_u, int max_distance) {
  int best = -1, best_distance = max_distance + 1;
  for (int index : candidates) {
    const cv::KeyPoint& candidate = right.keypoints[index];
    if (candidate.octave < kp.octave - 1 || candidate.octave > kp.octave + 1) continue;
    if (candidate.pt.x < min_u || candidate.pt.x > max_u) continue;
    const int distance = DescriptorDistance(descriptor, right.descriptors.ptr<uint8_t>(index));
    if (distance < best_distance) {
      best_distance = distance;
      best = index;
    }
  }
  return best;
}

struct Refined {
  bool ok = false;
  float u_right = 0;  // level-0 pixels
  float sad = 0;
};

// SAD search of +-range pixels around the descriptor match at kp's level, then a parabola through
// the best cost and its neighbours for the sub-pixel offset.
Refined RefineBySad(const cv::KeyPoint& kp, float u_right0, const ImageFeatures& left,
                    const ImageFeatures& right, const OrbExtractor& extractor,
                    const StereoMatchOptions& options) {
  Refined result;
  const int level = kp.octave;
  const cv::Mat& left_image = left.pyramid[level];
  const cv::Mat& right_image = right.pyramid[level];
  const double scale = extractor.ScaleFactor(level);
  const int w = options.sad_window_half_size, range = options.sad_search_half_range;
  const int u_left = static_cast<int>(std::lround(kp.pt.x / scale));
  const int v = static_cast<int>(std::lround(kp.pt.y / scale));
  const int u_right = static_cast<int>(std::lround(u_right0 / scale));
  if (v - w < 0 || v + w >= left_image.rows || v + w >= right_image.rows) return result;
  if (u_left - w < 0 || u_left + w >= left_image.cols) return result;
  if (u_right - range - w < 0 || u_right + range + w >= right_image.cols) return result;

#if defined(__SSE2__)
  const bool vectorized = u_right + range + w + SadOverread(w) < right_image.cols;
#else
  const bool vectorized = false;
  const auto CenteredSadSse2 = CenteredSad;
#endif
  CenteredPatch left_patch;
  FillCenteredPatch(left_image, u_left, v, w, left_patch);
  std::array<int, 61> costs{};
  int best_offset = 0, best_cost = INT32_MAX;
  for (int offset = -range; offset <= range; ++offset) {
    const int cost = vectorized ? CenteredSadSse2(left_patch, right_image, u_right + offset, v)
                                : CenteredSad(left_patch, right_image, u_right + offset, v);
    costs[offset + range] = cost;
    if (cost < best_cost) {
      best_cost = cost;
      best_offset = offset;
    }
  }
  // A minimum on the edge of the search range is not a minimum of the cost.
  if (best_offset == -range || best_offset == range) return result;
  const double c_prev = costs[best_offset + range - 1], c_best = costs[best_offset + range],
               c_next = costs[best_offset + range + 1];
  const double curvature = c_prev + c_next - 2 * c_best;
  const double delta = curvature > 0 ? (c_prev - c_next) / (2 * curvature) : 0.0;
  if (delta < -1 || delta > 1) return result;
  result.ok = true;
  result.u_right = static_cast<float>(scale * (u_right + best_offset + delta));
  result.sad = static_cast<float>(best_cost);
  return result;
}

}  // namespace

void StereoMatchOptions::Check() const {
  Require(max_descriptor_distance >= 0 && max_descriptor_distance <= 256,
          "max_descriptor_distance must be in [0, 256], got " +
              std::to_string(max_descriptor_distance));
  Require(sad_window_half_size >= 1 && sad_window_half_size <= 15,
          "sad_window_half_size must be in [1, 15], got " + std::to_string(sad_window_half_size));
  Require(sad_search_half_range >= 2 && sad_search_half_range <= 30,
          "sad_search_half_range must be in [2, 30], got " + std::to_string(sad_search_half_range));
  Require(min_depth >= 0 && std::isfinite(min_depth),
          "min_depth must be >= 0 metres, got " + std::to_string(min_depth));
}

int StereoFeatures::num_stereo_matches() const {
  return static_cast<int>(std::count_if(depth.begin(), depth.end(), [](float d) { return d > 0; }));
}

void MatchStereo(const ImageFeatures& right, const StereoCamera& camera,
                 const OrbExtractor& extractor, const StereoMatchOptions& options,
                 StereoFeatures& features) {
  options.Check();
  camera.Check();
  const ImageFeatures& left = features.left;
  const int num_left = static_cast<int>(left.keypoints.size());
  features.u_right.assign(num_left, -1.0f);
  features.depth.assign(num_left, -1.0f);
  features.right_index.assign(num_left, -1);
  features.num_right_keypoints = static_cast<int>(right.keypoints.size());
  if (num_left == 0 || right.keypoints.empty() || left.pyramid.empty()) return;
  if (left.pyramid.size() != right.pyramid.size() ||
      static_cast<int>(left.pyramid.size()) != extractor.num_levels()) {
    throw std::invalid_argument(
        "MatchStereo: left and right features come from different pyramids");
  }

  const double bf = camera.BaselineTimesFx();
  const double min_depth = options.min_depth > 0 ? options.min_depth : camera.baseline;
  const double min_disparity = 0.0, max_disparity = bf / min_depth;
  const std::vector<std::vector<int>> rows =
      RowIndex(right.keypoints, left.pyramid[0].rows, extractor);

  std::vector<std::pair<float, int>> sad_and_index;  // for the distance statistics
  sad_and_index.reserve(num_left);
  for (int i = 0; i < num_left; ++i) {
    const cv::KeyPoint& kp = left.keypoints[i];
    const int row = static_cast<int>(std::lround(kp.pt.y));
    if (row < 0 || row >= static_cast<int>(rows.size()) || rows[row].empty()) continue;
    const float min_u = static_cast<float>(kp.pt.x - max_disparity);
    const float max_u = static_cast<float>(kp.pt.x - min_disparity);
    if (max_u < 0) continue;
    const int best = BestDescriptorMatch(kp, left.descriptors.ptr<uint8_t>(i), rows[row], right,
                                         min_u, max_u, options.max_descriptor_distance);
    if (best < 0) continue;
    const Refined refined =
        RefineBySad(kp, right.keypoints[best].pt.x, left, right, extractor, options);
    if (!refined.ok) continue;
    float u_right = refined.u_right;
    double disparity = kp.pt.x - u_right;
    if (disparity < min_disparity || disparity >= max_disparity) continue;
    if (disparity <= 0) {  // at infinity: keep a tiny positive disparity (ORB-SLAM2 does)
      disparity = 0.01;
      u_right = static_cast<float>(kp.pt.x - disparity);
    }
    features.u_right[i] = u_right;
    features.depth[i] = static_cast<float>(bf / disparity);
    features.right_index[i] = best;
    sad_and_index.emplace_back(refined.sad, i);
  }
  if (sad_and_index.empty()) return;

  // Distance statistics: a patch cost far above the typical one marks a wrong match (repeated
  // texture, occlusion), whatever its descriptor distance was.
  std::sort(sad_and_index.begin(), sad_and_index.end());
  const float median = sad_and_index[sad_and_index.size() / 2].first;
  const float threshold = 1.5f * 1.4f * median;
  for (auto it = sad_and_index.rbegin(); it != sad_and_index.rend() && it->first > threshold;
       ++it) {
    features.u_right[it->second] = -1.0f;
    features.depth[it->second] = -1.0f;
    features.right_index[it->second] = -1;
  }
}

StereoFeatures ExtractStereoFeatures(const cv::Mat& left, const cv::Mat& right,
                                     const StereoCamera& camera, const OrbExtractor& extractor,
                                     const StereoMatchOptions& options) {
  StereoFeatures features;
  ImageFeatures right_features;
  tbb::task_group group;
  group.run([&] { features.left = extractor.Extract(left); });
  group.run([&] { right_features = extractor.Extract(right); });
  group.wait();
  MatchStereo(right_features, camera, extractor, options, features);
  return features;
}

}  // namespace planeloc
