#include "planeloc/map/plane_outline.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <string>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// Signed area (positive = counter-clockwise) of a 2-D ring.
double SignedArea(const std::vector<Eigen::Vector2d>& ring) {
  double twice = 0.0;
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const auto& a = ring[i];
    const auto& b = ring[(i + 1) % ring.size()];
    twice += a.x() * b.y() - a.y() * b.x();
  }
  return 0.5 * twice;
}

// Outer boundary (pixel coordinates) of the largest 8-connected component of `occupied`; ties go
// to the lowest label, i.e. the first component in raster order, so the result is deterministic.
std::vector<cv::Point> LargestComponentBoundary(const cv::Mat& occupied) {
  cv::Mat labels, stats, centroids;
  const int count = cv::connectedComponentsWithStats(occupied, labels, stats, centroids, 8, CV_32S);
  int best = 0;
  for (int label = 1; label < count; ++label) {
    if (best == 0 ||
        stats.at<int>(label, cv::CC_STAT_AREA) > stats.at<int>(best, cv::CC_STAT_AREA)) {
      best = label;
    }
  }
  if (best == 0) return {};
  cv::Mat mask = labels == best;
  std::vector<std::vector<cv::Point>> contours;
  cv::findContours(mask, contours, cv::RETR_EXTERNAL, cv::CHAIN_APPROX_NONE);
  if (contours.empty()) return {};
  // One 8-connected component has one outer contour; keep the longest should there be more.
  return *std::max_element(contours.begin(), contours.end(),
                           [](const auto& a, const auto& b) { return a.size() < b.size(); });
}

// Observed area in cells. A boundary cell is occupied however little of it the surface covers,
// half of it on average, so each occupied cell counts 1 - 0.5 per empty 4-neighbour: a W x H
// rectangle of cells gives (W - 1) x (H - 1), its extent between the outermost samples, instead of
// overshooting by half a cell all round (10.25^2 m^2 for a 10 x 10 m patch). The floor of 1/4 (a
// corner) keeps thin lines and isolated cells positive. `occupied` is padded (no border cells).
double CoveredCells(const cv::Mat& occupied) {
  double cells = 0.0;
  for (int r = 1; r + 1 < occupied.rows; ++r) {
    for (int c = 1; c + 1 < occupied.cols; ++c) {
      if (occupied.at<std::uint8_t>(r, c) == 0) continue;
      const int empty =
          (occupied.at<std::uint8_t>(r - 1, c) == 0) + (occupied.at<std::uint8_t>(r + 1, c) == 0) +
          (occupied.at<std::uint8_t>(r, c - 1) == 0) + (occupied.at<std::uint8_t>(r, c + 1) == 0);
      cells += std::max(0.25, 1.0 - 0.5 * empty);
    }
  }
  return cells;
}

}  // namespace

void PlaneOutlineOptions::Check() const {
  auto require = [](bool ok, const char* message) {
    if (!ok) throw OptionsError(std::string("PlaneOutlineOptions.") + message);
  };
  require(std::isfinite(cell_size) && cell_size > 0.0, "cell_size must be > 0 (metres)");
  require(closing_cells >= 0 && closing_cells <= 20, "closing_cells must be in [0, 20]");
  require(std::isfinite(simplify_cells) && simplify_cells >= 0.0, "simplify_cells must be >= 0");
  require(max_cells >= 1e4, "max_cells must be >= 1e4");
}

PlaneOutline2d ComputePlaneOutline2d(const std::vector<Eigen::Vector2d>& points,
                                     const PlaneOutlineOptions& options) {
  options.Check();
  PlaneOutline2d outline;
  if (points.empty()) return outline;
  Eigen::Vector2d lo = points.front(), hi = points.front();
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // A padding of closing_cells + 1 keeps the closing and the boundary away from the image border.
  const int pad = options.closing_cells + 1;
  double cell = options.cell_size;
  auto cells_for = [&](double c) {
    return ((hi.x() - lo.x()) / c + 1.0 + 2 * pad) * ((hi.y() - lo.y()) / c + 1.0 + 2 * pad);
  };
  if (cells_for(cell) > options.max_cells) cell *= std::sqrt(cells_for(cell) / options.max_cells);
  outline.cell_size = cell;
  const int cols = static_cast<int>(std::floor((hi.x() - lo.x()) / cell)) + 1 + 2 * pad;
  const int rows = static_cast<int>(std::floor((hi.y() - lo.y()) / cell)) + 1 + 2 * pad;
  cv::Mat occupied = cv::Mat::zeros(rows, cols, CV_8U);
  for (const auto& p : points) {
    const int col = static_cast<int>(std::floor((p.x() - lo.x()) / cell)) + pad;
    const int row = static_cast<int>(std::floor((p.y() - lo.y()) / cell)) + pad;
    occupied.at<std::uint8_t>(std::min(row, rows - 1), std::min(col, cols - 1)) = 255;
  }
  if (options.closing_cells > 0) {
    const int size = 2 * options.closing_cells + 1;
    const cv::Mat element = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(size, size));
    cv::morphologyEx(occupied, occupied, cv::MORPH_CLOSE, element);
  }
  outline.area = CoveredCells(occupied) * cell * cell;
  const std::vector<cv::Point> boundary = LargestComponentBoundary(occupied);
  std::vector<cv::Point> simplified;
  if (boundary.size() >= 3 && options.simplify_cells > 0.0) {
    cv::approxPolyDP(boundary, simplified, options.simplify_cells, /*closed=*/true);
  }
  if (simplified.size() < 3) simplified = boundary;
  for (const auto& q : simplified) {
    outline.ring.emplace_back(lo.x() + (q.x - pad + 0.5) * cell, lo.y() + (q.y - pad + 0.5) * cell);
  }
  if (SignedArea(outline.ring) < 0.0) std::reverse(outline.ring.begin(), outline.ring.end());
  return outline;
}

}  // namespace planeloc
