#include "planeloc/features/line_segments.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

void Require(bool condition, const std::string& what) {
  if (!condition) throw OptionsError("LsdOptions: " + what);
}

}  // namespace

void LsdOptions::Check() const {
  Require(min_length_px >= 0, "min_length_px must be >= 0, got " + std::to_string(min_length_px));
  Require(scale > 0 && scale <= 1, "scale must be in (0, 1], got " + std::to_string(scale));
  Require(sigma_scale > 0, "sigma_scale must be > 0, got " + std::to_string(sigma_scale));
  Require(quantization >= 0, "quantization must be >= 0, got " + std::to_string(quantization));
  Require(angle_tolerance_deg > 0 && angle_tolerance_deg < 180,
          "angle_tolerance_deg must be in (0, 180), got " + std::to_string(angle_tolerance_deg));
  Require(density_threshold > 0 && density_threshold <= 1,
          "density_threshold must be in (0, 1], got " + std::to_string(density_threshold));
}

std::vector<LineSegment> DetectLineSegments(const cv::Mat& grey, const LsdOptions& options) {
  options.Check();
  if (grey.empty() || grey.type() != CV_8UC1) {
    throw std::invalid_argument("DetectLineSegments: expected a non-empty CV_8UC1 image");
  }
  const int refine = options.advanced_refinement ? cv::LSD_REFINE_ADV : cv::LSD_REFINE_STD;
  cv::Ptr<cv::LineSegmentDetector> lsd = cv::createLineSegmentDetector(
      refine, options.scale, options.sigma_scale, options.quantization, options.angle_tolerance_deg,
      options.log_eps, options.density_threshold);
  std::vector<cv::Vec4f> lines;
  std::vector<double> widths, precisions, nfas;
  if (options.advanced_refinement) {
    lsd->detect(grey, lines, widths, precisions, nfas);
  } else {
    lsd->detect(grey, lines, widths, precisions);
  }
  // LSD works on the image resampled by `scale` and divides its coordinates by it, which puts a
  // point at pixel centre x at x + 0.5 - 0.5 / scale (an edge between pixels 149 and 150 comes
  // out at 149.375 for scale 0.8). Undone here: segments are in pixel-centre coordinates.
  const float to_centre = static_cast<float>(0.5 / options.scale - 0.5);
  std::vector<LineSegment> segments;
  segments.reserve(lines.size());
  for (size_t i = 0; i < lines.size(); ++i) {
    LineSegment segment;
    segment.start = Eigen::Vector2d(lines[i][0] + to_centre, lines[i][1] + to_centre);
    segment.end = Eigen::Vector2d(lines[i][2] + to_centre, lines[i][3] + to_centre);
    segment.width = i < widths.size() ? widths[i] : 0.0;
    if (options.advanced_refinement) {
      segment.precision_or_nfa = i < nfas.size() ? nfas[i] : 0.0;
    } else {
      segment.precision_or_nfa = i < precisions.size() ? precisions[i] : 0.0;
    }
    if (segment.Length() >= options.min_length_px) segments.push_back(segment);
  }
  std::stable_sort(segments.begin(), segments.end(),
                   [](const LineSegment& a, const LineSegment& b) {
                     if (a.Length() != b.Length()) return a.Length() > b.Length();
                     if (a.start.x() != b.start.x()) return a.start.x() < b.start.x();
                     return a.start.y() < b.start.y();
                   });
  return segments;
}

}  // namespace planeloc
