#include "planeloc/features/orb_extractor.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "planeloc/features/keypoint_distribution.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr int kPatchSize = 31;  // BRIEF patch diameter at the keypoint's level
constexpr int kHalfPatchSize = kPatchSize / 2;
// Keypoints keep this distance (level pixels) to the level border, so that the rotated BRIEF
// patch (radius up to 15·sqrt(2)) and the orientation disc stay inside the image.
constexpr int kEdgeThreshold = 19;
// FAST needs a 3-pixel ring: detecting in [kEdgeThreshold - 3, size - kEdgeThreshold + 3) puts
// corners at >= kEdgeThreshold from the border.
constexpr int kDetectionBorder = kEdgeThreshold - 3;
constexpr int kCellSize = 30;  // FAST cell side, level pixels
constexpr int kDescriptorBytes = 32;

void Require(bool condition, const std::string& what) {
  if (!condition) throw OptionsError("OrbOptions: " + what);
}

// Half-widths of the rows of the orientation disc of radius kHalfPatchSize. The upper rows are
// the transpose of the lower ones, so the disc is symmetric under u <-> v and a 90-degree rotation
// of the image rotates the intensity centroid exactly.
const std::array<int, kHalfPatchSize + 1>& DiscHalfWidths() {
  static const std::array<int, kHalfPatchSize + 1> widths = [] {
    std::array<int, kHalfPatchSize + 1> w{};
    const double r = kHalfPatchSize;
    const int v_direct = static_cast<int>(std::floor(r * std::sqrt(2.0) / 2 + 1));
    const int v_transposed = static_cast<int>(std::ceil(r * std::sqrt(2.0) / 2));
    for (int v = 0; v <= v_direct; ++v)
      w[v] = static_cast<int>(std::lround(std::sqrt(r * r - v * v)));
    for (int v = kHalfPatchSize; v >= v_transposed; --v) {
      int u = 0;
      while (u + 1 <= v_direct && w[u + 1] >= v) ++u;
      w[v] = u;
    }
    return w;
  }();
  return widths;
}

// Orientation by intensity centroid over the disc, degrees in [0, 360).
float IntensityCentroidAngle(const cv::Mat& image, cv::Point2f pt) {
  const auto& half_widths = DiscHalfWidths();
  const int x = cvRound(pt.x), y = cvRound(pt.y);
  const uchar* center = image.ptr<uchar>(y) + x;
  const int step = static_cast<int>(image.step1());
  int m_10 = 0, m_01 = 0;
  for (int u = -kHalfPatchSize; u <= kHalfPatchSize; ++u) m_10 += u * center[u];
  for (int v = 1; v <= kHalfPatchSize; ++v) {
    int v_sum = 0;  // sum over the row pair (+v, -v): weight +v below, -v above
    const int d = half_widths[v];
    for (int u = -d; u <= d; ++u) {
      const int below = center[u + v * step], above = center[u - v * step];
      v_sum += below - above;
      m_10 += u * (below + above);
    }
    m_01 += v * v_sum;
  }
  return cv::fastAtan2(static_cast<float>(m_01), static_cast<float>(m_10));
}

// FAST corners of one level on a grid of cells: each cell first with the initial threshold, then,
// if it found nothing, with the minimum one (textureless regions still get corners). The initial
// pass runs once over the whole level and is binned into cells: per-cell FAST calls cost ~3x more
// (call overhead and overlapping margins), and the minimum-threshold pass runs only on the empty
// cells, which keeps the expensive low threshold off the textured parts.
std::vector<cv::KeyPoint> DetectCellCorners(const cv::Mat& image, const OrbOptions& options,
                                            cv::Rect2f& area) {
  const int min_x = kDetectionBorder, min_y = kDetectionBorder;
  const int max_x = image.cols - kDetectionBorder, max_y = image.rows - kDetectionBorder;
  area = cv::Rect2f(static_cast<float>(min_x), static_cast<float>(min_y),
                    static_cast<float>(max_x - min_x), static_cast<float>(max_y - min_y));
  std::vector<cv::KeyPoint> corners;
  if (max_x - min_x < 7 || max_y - min_y < 7) return corners;
  const int num_cols = std::max(1, (max_x - min_x) / kCellSize);
  const int num_rows = std::max(1, (max_y - min_y) / kCellSize);
  const int cell_w = (max_x - min_x + num_cols - 1) / num_cols;
  const int cell_h = (max_y - min_y + num_rows - 1) / num_rows;

  // FAST ignores a 3-pixel margin of the image it is given: on [min, max) it detects in
  // [min + 3, max - 3), and cell (row, col) owns [min + 3 + col * cell_w, ... + cell_w).
  cv::FAST(image(cv::Range(min_y, max_y), cv::Range(min_x, max_x)), corners,
           options.initial_fast_threshold, true);
  std::vector<char> cell_has_corner(num_rows * num_cols, 0);
  for (cv::KeyPoint& corner : corners) {
    corner.pt.x += static_cast<float>(min_x);
    corner.pt.y += static_cast<float>(min_y);
    const int col = std::min(static_cast<int>(corner.pt.x - min_x - 3) / cell_w, num_cols - 1);
    const int row = std::min(static_cast<int>(corner.pt.y - min_y - 3) / cell_h, num_rows - 1);
    cell_has_corner[row * num_cols + col] = 1;
  }
  std::vector<cv::KeyPoint> cell_corners;
  for (int row = 0; row < num_rows; ++row) {
    const int y0 = min_y + row * cell_h;
    if (y0 >= max_y - 6) continue;
    const int y1 = std::min(y0 + cell_h + 6, max_y);
    for (int col = 0; col < num_cols; ++col) {
      if (cell_has_corner[row * num_cols + col]) continue;
      const int x0 = min_x + col * cell_w;
      if (x0 >= max_x - 6) continue;
      const int x1 = std::min(x0 + cell_w + 6, max_x);
      cv::FAST(image(cv::Range(y0, y1), cv::Range(x0, x1)), cell_corners,
               options.min_fast_threshold, true);
      for (cv::KeyPoint& corner : cell_corners) {
        corner.pt.x += static_cast<float>(x0);
        corner.pt.y += static_cast<float>(y0);
        corners.push_back(corner);
      }
    }
  }
  return corners;
}

// Rotated BRIEF (the standard 256-pair ORB pattern) of `keypoints` (level pixels, angle set) on
// `image`. cv::ORB::compute with provided keypoints keeps their angle, smooths the level with
// GaussianBlur(7x7, sigma 2, reflect-101) and evaluates the rotated pattern; it drops keypoints
// closer than its edge threshold to the border, which is why the rows are mapped back through
// class_id. Rows of dropped keypoints (none with our border) are zero.
cv::Mat ComputeRotatedBrief(const cv::Mat& image, const std::vector<cv::KeyPoint>& keypoints) {
  cv::Mat descriptors = cv::Mat::zeros(static_cast<int>(keypoints.size()), kDescriptorBytes, CV_8U);
  if (keypoints.empty()) return descriptors;
  std::vector<cv::KeyPoint> query(keypoints);
  for (int i = 0; i < static_cast<int>(query.size()); ++i) {
    query[i].octave = 0;  // one level per call: `image` is the level itself
    query[i].class_id = i;
  }
  cv::Ptr<cv::ORB> orb = cv::ORB::create(static_cast<int>(query.size()), 1.2f, 1, kEdgeThreshold, 0,
                                         2, cv::ORB::HARRIS_SCORE, kPatchSize);
  cv::Mat computed;
  orb->compute(image, query, computed);
  for (int row = 0; row < static_cast<int>(query.size()); ++row) {
    computed.row(row).copyTo(descriptors.row(query[row].class_id));
  }
  return descriptors;
}

}  // namespace

void OrbOptions::Check() const {
  Require(num_features > 0, "num_features must be > 0, got " + std::to_string(num_features));
  Require(scale_factor > 1.0 && scale_factor < 4.0,
          "scale_factor must be in (1, 4), got " + std::to_string(scale_factor));
  Require(num_levels >= 1 && num_levels <= 20,
          "num_levels must be in [1, 20], got " + std::to_string(num_levels));
  Require(
      initial_fast_threshold >= 1 && initial_fast_threshold <= 254,
      "initial_fast_threshold must be in [1, 254], got " + std::to_string(initial_fast_threshold));
  Require(min_fast_threshold >= 1 && min_fast_threshold <= initial_fast_threshold,
          "min_fast_threshold must be in [1, initial_fast_threshold], got " +
              std::to_string(min_fast_threshold));
}

OrbExtractor::OrbExtractor(const OrbOptions& options) : options_(options) {
  options_.Check();
  const int n = options_.num_levels;
  scale_factors_.resize(n);
  level_sigma2_.resize(n);
  for (int level = 0; level < n; ++level) {
    scale_factors_[level] = std::pow(options_.scale_factor, level);
    level_sigma2_[level] = scale_factors_[level] * scale_factors_[level];
  }
  // Budget per level: a geometric series with ratio 1/scale_factor summing to num_features
  // (ORB-SLAM2's split: proportional to the level's side length, not its area, which keeps more
  // features on the coarse levels than an area split would).
  const double ratio = 1.0 / options_.scale_factor;
  double per_level = options_.num_features * (1 - ratio) / (1 - std::pow(ratio, n));
  features_per_level_.assign(n, 0);
  int assigned = 0;
  for (int level = 0; level + 1 < n; ++level) {
    features_per_level_[level] = static_cast<int>(std::lround(per_level));
    assigned += features_per_level_[level];
    per_level *= ratio;
  }
  features_per_level_[n - 1] = std::max(options_.num_features - assigned, 0);
}

std::vector<cv::Mat> OrbExtractor::BuildPyramid(const cv::Mat& grey) const {
  std::vector<cv::Mat> pyramid(options_.num_levels);
  pyramid[0] = grey.clone();  // owned: the caller may reuse its image buffer
  for (int level = 1; level < options_.num_levels; ++level) {
    const double inverse_scale = 1.0 / scale_factors_[level];
    const cv::Size size(static_cast<int>(std::lround(grey.cols * inverse_scale)),
                        static_cast<int>(std::lround(grey.rows * inverse_scale)));
    if (size.width < 1 || size.height < 1) {
      pyramid[level] =
          cv::Mat(std::max(size.height, 1), std::max(size.width, 1), CV_8U, cv::Scalar(0));
      continue;
    }
    cv::resize(pyramid[level - 1], pyramid[level], size, 0, 0, cv::INTER_LINEAR);
  }
  return pyramid;
}

OrbExtractor::LevelFeatures OrbExtractor::ExtractLevel(const cv::Mat& image, int level) const {
  LevelFeatures result;
  cv::Rect2f area;
  std::vector<cv::KeyPoint> corners = DetectCellCorners(image, options_, area);
  const std::vector<int> kept = DistributeQuadtree(corners, area, features_per_level_[level]);
  result.keypoints.reserve(kept.size());
  const float size = static_cast<float>(kPatchSize * scale_factors_[level]);
  for (int index : kept) {
    cv::KeyPoint keypoint = corners[index];
    keypoint.angle = IntensityCentroidAngle(image, keypoint.pt);
    keypoint.octave = level;
    keypoint.size = size;
    result.keypoints.push_back(keypoint);
  }
  result.descriptors = ComputeRotatedBrief(image, result.keypoints);
  const float scale = static_cast<float>(scale_factors_[level]);
  for (cv::KeyPoint& keypoint : result.keypoints) keypoint.pt *= scale;  // to level 0
  return result;
}

ImageFeatures OrbExtractor::Extract(const cv::Mat& grey) const {
  if (grey.empty() || grey.type() != CV_8UC1) {
    throw std::invalid_argument("OrbExtractor::Extract: expected a non-empty CV_8UC1 image");
  }
  ImageFeatures features;
  features.pyramid = BuildPyramid(grey);
  std::vector<LevelFeatures> levels(options_.num_levels);
  // Levels are independent; results are concatenated in level order, so the output does not
  // depend on the scheduling.
  tbb::parallel_for(0, options_.num_levels, [&](int level) {
    levels[level] = ExtractLevel(features.pyramid[level], level);
  });
  size_t total = 0;
  for (const LevelFeatures& level : levels) total += level.keypoints.size();
  features.keypoints.reserve(total);
  features.descriptors.create(static_cast<int>(total), kDescriptorBytes, CV_8U);
  int row = 0;
  for (LevelFeatures& level : levels) {
    features.keypoints.insert(features.keypoints.end(), level.keypoints.begin(),
                              level.keypoints.end());
    if (level.descriptors.rows > 0) {
      level.descriptors.copyTo(features.descriptors.rowRange(row, row + level.descriptors.rows));
    }
    row += level.descriptors.rows;
  }
  return features;
}

int DescriptorDistance(const cv::Mat& a, const cv::Mat& b) {
  return DescriptorDistance(a.ptr<uint8_t>(), b.ptr<uint8_t>());
}

int DescriptorDistance(const uint8_t* a, const uint8_t* b) {
  // Bit-parallel popcount: the build targets baseline x86-64 without the POPCNT instruction, where
  // std::popcount becomes a library call per word (8 % of the stereo matching time).
  int distance = 0;
  for (int i = 0; i < kDescriptorBytes; i += 8) {
    uint64_t wa, wb;
    std::memcpy(&wa, a + i, 8);
    std::memcpy(&wb, b + i, 8);
    uint64_t x = wa ^ wb;
    x = x - ((x >> 1) & 0x5555555555555555ull);
    x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
    x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0full;
    distance += static_cast<int>((x * 0x0101010101010101ull) >> 56);
  }
  return distance;
}

}  // namespace planeloc
