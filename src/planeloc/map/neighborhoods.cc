#include "planeloc/map/neighborhoods.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "planeloc/geometry/morton.h"

namespace planeloc {
namespace {

constexpr int kBitsPerAxis = 21;  // 3 * 21 = 63 bits of Morton key
constexpr std::int64_t kMaxCell = (std::int64_t{1} << kBitsPerAxis) - 1;

std::uint64_t MortonKey(std::int64_t x, std::int64_t y, std::int64_t z) {
  return MortonKey3(static_cast<std::uint64_t>(x), static_cast<std::uint64_t>(y),
                    static_cast<std::uint64_t>(z));
}

// Points sorted by the Morton key of their cell; cells are runs of equal keys.
struct Grid {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  double cell_size = 1.0;
  std::vector<std::int32_t> order;        // sorted position -> point index
  std::vector<std::uint64_t> cell_keys;   // ascending, one per non-empty cell
  std::vector<std::int64_t> cell_starts;  // size cells + 1, positions in `order`
  std::vector<Eigen::Matrix<std::int64_t, 3, 1>> cell_coords;
};

Grid BuildGrid(const std::vector<Eigen::Vector3d>& points, double min_cell_size) {
  if (!(min_cell_size > 0.0)) throw std::invalid_argument("cell size must be > 0");
  if (points.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
    throw std::invalid_argument("more than 2^31 - 1 points");
  }
  Grid grid;
  if (points.empty()) {
    grid.cell_starts = {0};
    return grid;
  }
  Eigen::Vector3d lo = points.front(), hi = points.front();
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      throw std::invalid_argument("point " + std::to_string(i) + " is not finite");
    }
    lo = lo.cwiseMin(points[i]);
    hi = hi.cwiseMax(points[i]);
  }
  grid.origin = lo;
  // Larger cells stay correct for a radius search (the 27 cells still cover the ball); they are
  // only needed for maps wider than 2^21 cells.
  grid.cell_size =
      std::max(min_cell_size, (hi - lo).maxCoeff() / static_cast<double>(kMaxCell - 1));
  const std::size_t n = points.size();
  std::vector<std::pair<std::uint64_t, std::int32_t>> keyed(n);
  const double inv_cell = 1.0 / grid.cell_size;
  tbb::parallel_for(std::size_t{0}, n, [&](std::size_t i) {
    const Eigen::Vector3d c = ((points[i] - lo) * inv_cell).array().floor();
    keyed[i] = {MortonKey(std::min<std::int64_t>(static_cast<std::int64_t>(c.x()), kMaxCell),
                          std::min<std::int64_t>(static_cast<std::int64_t>(c.y()), kMaxCell),
                          std::min<std::int64_t>(static_cast<std::int64_t>(c.z()), kMaxCell)),
                static_cast<std::int32_t>(i)};
  });
  // (key, index) pairs are unique, so the parallel sort is deterministic.
  tbb::parallel_sort(keyed.begin(), keyed.end());
  grid.order.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    grid.order[k] = keyed[k].second;
    if (k == 0 || keyed[k].first != keyed[k - 1].first) {
      grid.cell_keys.push_back(keyed[k].first);
      grid.cell_starts.push_back(static_cast<std::int64_t>(k));
      const Eigen::Vector3d c = ((points[keyed[k].second] - lo) * inv_cell).array().floor();
      grid.cell_coords.push_back(c.cast<std::int64_t>().cwiseMin(kMaxCell));
    }
  }
  grid.cell_starts.push_back(static_cast<std::int64_t>(n));
  return grid;
}

// Cell index of a key, or -1.
std::int64_t FindCell(const Grid& grid, std::uint64_t key) {
  const auto it = std::lower_bound(grid.cell_keys.begin(), grid.cell_keys.end(), key);
  if (it == grid.cell_keys.end() || *it != key) return -1;
  return it - grid.cell_keys.begin();
}

// For every point i, calls visit(i, candidates, d2, count) with the points of the 27 cells
// around i's cell and their squared distances d2[c] to i (i itself included). Cells are
// processed TBB-parallel; visits of one point never overlap.
template <typename Visit>
void SweepCells(const Grid& grid, const std::vector<Eigen::Vector3d>& points, Visit&& visit) {
  const std::size_t cells = grid.cell_keys.size();
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, cells, 16),
      [&](const tbb::blocked_range<std::size_t>& range) {
        std::vector<double> cx, cy, cz;
        std::vector<std::int32_t> cid;
        std::vector<double> d2;
        for (std::size_t cell = range.begin(); cell != range.end(); ++cell) {
          cx.clear();
          cy.clear();
          cz.clear();
          cid.clear();
          const auto& coords = grid.cell_coords[cell];
          for (int dz = -1; dz <= 1; ++dz) {
            for (int dy = -1; dy <= 1; ++dy) {
              for (int dx = -1; dx <= 1; ++dx) {
                const Eigen::Matrix<std::int64_t, 3, 1> c =
                    coords + Eigen::Matrix<std::int64_t, 3, 1>(dx, dy, dz);
                if ((c.array() < 0).any() || (c.array() > kMaxCell).any()) continue;
                const std::int64_t other = FindCell(grid, MortonKey(c.x(), c.y(), c.z()));
                if (other < 0) continue;
                for (auto k = grid.cell_starts[other]; k < grid.cell_starts[other + 1]; ++k) {
                  const std::int32_t j = grid.order[static_cast<std::size_t>(k)];
                  const Eigen::Vector3d& q = points[static_cast<std::size_t>(j)];
                  cx.push_back(q.x());
                  cy.push_back(q.y());
                  cz.push_back(q.z());
                  cid.push_back(j);
                }
              }
            }
          }
          const std::size_t count = cid.size();
          d2.resize(count);
          for (auto k = grid.cell_starts[cell]; k < grid.cell_starts[cell + 1]; ++k) {
            const std::int32_t i = grid.order[static_cast<std::size_t>(k)];
            const Eigen::Vector3d& p = points[static_cast<std::size_t>(i)];
            const double px = p.x(), py = p.y(), pz = p.z();
            // Absolute coordinates: d2(i, j) and d2(j, i) are the same float, so the neighbour
            // relation is exactly symmetric.
            for (std::size_t c = 0; c < count; ++c) {  // vectorizes
              const double ex = cx[c] - px, ey = cy[c] - py, ez = cz[c] - pz;
              d2[c] = ex * ex + ey * ey + ez * ez;
            }
            visit(i, cid.data(), d2.data(), count);
          }
        }
      });
}

}  // namespace

std::vector<std::int32_t> MortonOrder(const std::vector<Eigen::Vector3d>& points,
                                      double cell_size) {
  return BuildGrid(points, cell_size).order;
}

Neighborhoods FindNeighborhoods(const std::vector<Eigen::Vector3d>& points, double radius,
                                std::size_t max_neighbors) {
  if (!(radius > 0.0)) throw std::invalid_argument("FindNeighborhoods: radius must be > 0");
  const Grid grid = BuildGrid(points, radius);
  const std::size_t n = points.size();
  Neighborhoods hoods;
  hoods.radius = radius;
  hoods.offsets.assign(n + 1, 0);
  if (n == 0) return hoods;
  // Two sweeps over the cells, the first counting, the second writing every row straight into
  // its place: no intermediate lists, so the peak memory is one neighbourhood graph (the distance
  // tests are cheap next to a second copy of ~180 indices a point).
  const double radius2 = radius * radius;
  std::vector<std::int64_t> row_sizes(n);
  SweepCells(
      grid, points,
      [&](std::int32_t i, const std::int32_t* candidates, const double* d2, std::size_t count) {
        std::int64_t size = 0;
        for (std::size_t c = 0; c < count; ++c) {
          size += (d2[c] <= radius2) & (candidates[c] != i);
        }
        if (max_neighbors > 0) size = std::min(size, static_cast<std::int64_t>(max_neighbors));
        row_sizes[static_cast<std::size_t>(i)] = size;
      });
  for (std::size_t i = 0; i < n; ++i) hoods.offsets[i + 1] = hoods.offsets[i] + row_sizes[i];
  std::vector<std::int64_t>().swap(row_sizes);
  hoods.indices.resize(static_cast<std::size_t>(hoods.offsets.back()));
  SweepCells(
      grid, points,
      [&](std::int32_t i, const std::int32_t* candidates, const double* d2, std::size_t count) {
        const auto row = static_cast<std::size_t>(i);
        std::int32_t* dst = hoods.indices.data() + hoods.offsets[row];
        const auto size = static_cast<std::size_t>(hoods.offsets[row + 1] - hoods.offsets[row]);
        if (max_neighbors == 0 || size < max_neighbors) {
          for (std::size_t c = 0; c < count; ++c) {
            if (d2[c] <= radius2 && candidates[c] != i) *dst++ = candidates[c];
          }
          return;
        }
        // Possibly capped: the `size` nearest by (distance, index).
        thread_local std::vector<std::pair<double, std::int32_t>> near;
        near.clear();
        for (std::size_t c = 0; c < count; ++c) {
          if (d2[c] <= radius2 && candidates[c] != i) near.emplace_back(d2[c], candidates[c]);
        }
        std::nth_element(near.begin(), near.begin() + static_cast<std::ptrdiff_t>(size - 1),
                         near.end());
        near.resize(size);
        std::sort(near.begin(), near.end());
        for (const auto& [distance2, j] : near) *dst++ = j;
      });
  return hoods;
}

}  // namespace planeloc
