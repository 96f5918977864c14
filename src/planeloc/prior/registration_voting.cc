#include "planeloc/prior/registration_voting.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

namespace planeloc {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// A point votes for a facade only within this height (metres) of the facade's outline.
constexpr double kHeightMargin = 0.5;

}  // namespace

double VoteVerticalShift(const std::vector<double>& shifts, double range, double bin) {
  const int bins = static_cast<int>(std::ceil(2.0 * range / bin)) + 1;
  std::vector<double> histogram(bins, 0.0);
  for (const double shift : shifts) {
    const int k = static_cast<int>(std::lround((shift + range) / bin));
    if (k >= 0 && k < bins) histogram[k] += 1.0;
  }
  double best_shift = 0, best_count = 0;
  for (int k = 0; k < bins; ++k) {
    double count = histogram[k];
    if (k > 0) count += 0.5 * histogram[k - 1];
    if (k + 1 < bins) count += 0.5 * histogram[k + 1];
    if (count > best_count) {
      best_count = count;
      best_shift = k * bin - range;
    }
  }
  return best_shift;
}

HoughFacade MakeHoughFacade(const Plane& plane, const std::vector<Eigen::Vector3d>& outline,
                            const Eigen::Vector3d& up) {
  HoughFacade facade;
  facade.plane = plane;
  facade.normal = plane.normal - plane.normal.dot(up) * up;
  facade.normal_norm = facade.normal.norm();
  facade.normal /= facade.normal_norm;
  facade.along = up.cross(facade.normal);
  facade.along_lo = facade.height_lo = -kInf;
  facade.along_hi = facade.height_hi = kInf;
  if (!outline.empty()) {
    facade.along_lo = facade.height_lo = kInf;
    facade.along_hi = facade.height_hi = -kInf;
    for (const Eigen::Vector3d& x : outline) {
      facade.along_lo = std::min(facade.along_lo, x.dot(facade.along));
      facade.along_hi = std::max(facade.along_hi, x.dot(facade.along));
      facade.height_lo = std::min(facade.height_lo, x.dot(up));
      facade.height_hi = std::max(facade.height_hi, x.dot(up));
    }
  }
  return facade;
}

namespace {

// The strongest local maxima (options.peaks_per_heading) of one heading's accumulator after a
// 3x3 box filter (a true shift often falls on a cell border); `smoothed` is scratch space.
std::vector<HeadingShiftPeak> HeadingPeaks(const std::vector<float>& accumulator, int nx, int ny,
                                           double heading, const ShiftGrid& grid,
                                           const HoughOptions& options,
                                           std::vector<float>& smoothed) {
  // 3x3 box filter (a true shift often falls on a cell border), then local maxima.
  const auto inside = [&](int x, int y) { return x >= 0 && y >= 0 && x < nx && y < ny; };
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      float sum = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if (inside(ix + dx, iy + dy)) sum += accumulator[(iy + dy) * nx + ix + dx];
        }
      }
      smoothed[iy * nx + ix] = sum;
    }
  }
  std::vector<HeadingShiftPeak> local;
  for (int iy = 0; iy < ny; ++iy) {
    for (int ix = 0; ix < nx; ++ix) {
      const float value = smoothed[iy * nx + ix];
      if (value <= 0) continue;
      bool is_max = true;
      for (int dy = -1; dy <= 1 && is_max; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if ((dx || dy) && inside(ix + dx, iy + dy) &&
              smoothed[(iy + dy) * nx + ix + dx] > value) {
            is_max = false;
            break;
          }
        }
      }
      if (!is_max) continue;
      HeadingShiftPeak peak;
      peak.votes = value;
      peak.heading = heading;
      peak.shift_xy = (ix * grid.cell - grid.half_range[0]) * grid.axis[0] +
                      (iy * grid.cell - grid.half_range[1]) * grid.axis[1];
      local.push_back(peak);
    }
  }
  std::sort(local.begin(), local.end(),
            [](const HeadingShiftPeak& a, const HeadingShiftPeak& b) { return a.votes > b.votes; });
  if (static_cast<int>(local.size()) > options.peaks_per_heading) {
    local.resize(options.peaks_per_heading);
  }
  return local;
}

}  // namespace

std::vector<HeadingShiftPeak> VoteHeadingAndShift(
    const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& pivot,
    const Eigen::Vector3d& up, const std::vector<HoughFacade>& facades,
    const std::vector<double>& headings, const ShiftGrid& grid, const HoughOptions& options) {
  const int nx = grid.cells[0], ny = grid.cells[1];
  const double reach = std::max(grid.half_range[0], grid.half_range[1]) + 1.0;
  const double span = std::hypot(grid.half_range[0], grid.half_range[1]);
  std::vector<float> accumulator(static_cast<std::size_t>(nx) * ny);
  std::vector<float> smoothed(accumulator.size());
  std::vector<HeadingShiftPeak> peaks;
  for (const double heading : headings) {
    const Eigen::Matrix3d rotation = Eigen::AngleAxisd(heading, up).toRotationMatrix();
    std::fill(accumulator.begin(), accumulator.end(), 0.0f);
    for (const Eigen::Vector3d& point : points) {
      const Eigen::Vector3d p = rotation * (point - pivot) + pivot;
      const double height = p.dot(up);
      for (const HoughFacade& facade : facades) {
        // Shift s along the horizontal normal that puts p on the facade.
        const double s = -facade.plane.SignedDistance(p) / facade.normal_norm;
        if (std::abs(s) > reach) continue;
        if (height < facade.height_lo - kHeightMargin || height > facade.height_hi + kHeightMargin)
          continue;
        // Shift = s normal + tau along; the shifted point must stay within the facade's extent.
        const double along = p.dot(facade.along);
        const double tau_lo = facade.along_lo - options.outline_margin - along;
        const double tau_hi = facade.along_hi + options.outline_margin - along;
        const Eigen::Vector2d origin(s * facade.normal.dot(grid.axis[0]),
                                     s * facade.normal.dot(grid.axis[1]));
        const Eigen::Vector2d direction(facade.along.dot(grid.axis[0]),
                                        facade.along.dot(grid.axis[1]));
        const double t0 = std::max(tau_lo, -span), t1 = std::min(tau_hi, span);
        int last = -1;
        for (double tau = t0; tau <= t1; tau += 0.7 * grid.cell) {
          const Eigen::Vector2d x = origin + tau * direction;
          const int ix = static_cast<int>(std::lround((x(0) + grid.half_range[0]) / grid.cell));
          const int iy = static_cast<int>(std::lround((x(1) + grid.half_range[1]) / grid.cell));
          if (ix < 0 || iy < 0 || ix >= nx || iy >= ny) continue;
          const int index = iy * nx + ix;
          if (index == last) continue;  // one vote per cell and facade
          accumulator[index] += 1.0f;
          last = index;
        }
      }
    }
    std::vector<HeadingShiftPeak> local =
        HeadingPeaks(accumulator, nx, ny, heading, grid, options, smoothed);
    peaks.insert(peaks.end(), local.begin(), local.end());
  }
  std::stable_sort(
      peaks.begin(), peaks.end(),
      [](const HeadingShiftPeak& a, const HeadingShiftPeak& b) { return a.votes > b.votes; });
  return peaks;
}

}  // namespace planeloc
