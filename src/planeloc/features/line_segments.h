// Straight line segments by LSD (von Gioi et al.'s Line Segment Detector, through OpenCV's
// cv::createLineSegmentDetector), for plane boundaries and structure cues.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

namespace planeloc {

struct LineSegment {
  // Pixels (u right, v down), pixel centres at integers: an edge between columns 149 and 150
  // lies at u = 149.5, whatever LsdOptions::scale.
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  Eigen::Vector2d end = Eigen::Vector2d::Zero();  // pixels; LSD orients start->end so that
                                                  // the brighter side is on the left
  double width = 0;                               // pixels, width of the supporting region
  double precision_or_nfa = 0;  // angle precision (standard refinement), or -log10(NFA) with
                                // the advanced refinement
  double Length() const { return (end - start).norm(); }
};

struct LsdOptions {
  double min_length_px = 20.0;       // shorter segments are dropped, pixels
  bool advanced_refinement = false;  // LSD_REFINE_ADV (slower; fills -log10(NFA))
  double scale = 0.8;                // image scale LSD works at, (0, 1]
  double sigma_scale = 0.6;          // Gaussian sigma = sigma_scale / scale
  double quantization = 2.0;         // bound on the gradient quantization error, grey levels
  double angle_tolerance_deg = 22.5;
  double log_eps = 0.0;            // detection threshold on -log10(NFA) (advanced only)
  double density_threshold = 0.7;  // minimum density of aligned points in the rectangle, (0, 1]
  // Throws planeloc::OptionsError naming the field.
  void Check() const;
};

// Segments of a CV_8UC1 image, longest first (ties by position, so the order is deterministic).
std::vector<LineSegment> DetectLineSegments(const cv::Mat& grey, const LsdOptions& options);

}  // namespace planeloc
