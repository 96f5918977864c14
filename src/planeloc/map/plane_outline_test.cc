#include "planeloc/map/plane_outline.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "planeloc/geometry/plane.h"
#include "planeloc/map/plane_extraction.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

// Grid of points with `spacing` over [x0, x1] x [y0, y1], skipping those `skip` returns true for.
template <typename Skip>
void AddGrid(double x0, double x1, double y0, double y1, double spacing,
             std::vector<Eigen::Vector2d>& out, Skip skip) {
  const int nx = static_cast<int>(std::round((x1 - x0) / spacing));
  const int ny = static_cast<int>(std::round((y1 - y0) / spacing));
  for (int i = 0; i <= nx; ++i) {
    for (int j = 0; j <= ny; ++j) {
      const Eigen::Vector2d p(x0 + i * spacing, y0 + j * spacing);
      if (!skip(p)) out.push_back(p);
    }
  }
}

void AddGrid(double x0, double x1, double y0, double y1, double spacing,
             std::vector<Eigen::Vector2d>& out) {
  AddGrid(x0, x1, y0, y1, spacing, out, [](const Eigen::Vector2d&) { return false; });
}

// L shape: a 10 x 4 m and a 4 x 10 m rectangle overlapping in their common 4 x 4 m corner, i.e.
// a union of 10 * 4 + 4 * 10 - 4 * 4 = 64 m^2 whose convex hull is 100 - 6 * 6 / 2 = 82 m^2.
std::vector<Eigen::Vector2d> LShape() {
  std::vector<Eigen::Vector2d> points;
  AddGrid(0.0, 10.0, 0.0, 4.0, 0.1, points);
  AddGrid(0.0, 4.0, 4.1, 10.0, 0.1, points);
  return points;
}

TEST(PlaneOutline, LShapeAreaFollowsTheShapeNotTheHull) {
  const auto points = LShape();
  const PlaneOutline2d outline = ComputePlaneOutline2d(points, PlaneOutlineOptions());
  const double hull_area = PolygonArea2d(ConvexHull2d(points));
  EXPECT_NEAR(outline.area, 64.0, 0.05 * 64.0);
  EXPECT_NEAR(hull_area, 82.0, 1.0);
  EXPECT_GT(hull_area, 1.2 * outline.area);  // the convex hull fills the L's missing corner
  // The ring is the L (6 corners after simplification, a few more allowed for raster steps) and
  // its area is the L's, far below the hull's.
  EXPECT_GE(outline.ring.size(), 6u);
  EXPECT_LE(outline.ring.size(), 10u);
  EXPECT_NEAR(PolygonArea2d(outline.ring), 64.0, 0.05 * 64.0);
  EXPECT_LT(PolygonArea2d(outline.ring), 0.85 * hull_area);
  // No vertex in the empty corner (x > 4.5 and y > 4.5).
  for (const auto& q : outline.ring) EXPECT_FALSE(q.x() > 4.5 && q.y() > 4.5) << q.transpose();
}

TEST(PlaneOutline, VerticesAreOnThePlaneAndNearInputPoints) {
  // The L on a tilted plane, through plane coordinates as ExtractPlanes builds them.
  const Eigen::Vector3d n = Eigen::Vector3d(0.3, -0.9, 0.2).normalized();
  const Eigen::Vector3d u = n.cross(Eigen::Vector3d::UnitX()).normalized();
  const Eigen::Vector3d v = n.cross(u);
  const Eigen::Vector3d origin(12.0, -3.0, 40.0);
  const Plane plane = Plane::FromPointAndNormal(origin, n);
  const auto flat = LShape();
  const PlaneOutlineOptions options;
  const PlaneOutline2d outline = ComputePlaneOutline2d(flat, options);
  ASSERT_GE(outline.ring.size(), 3u);
  for (const auto& q : outline.ring) {
    const Eigen::Vector3d vertex = origin + q.x() * u + q.y() * v;
    EXPECT_LT(std::abs(n.dot(vertex) + plane.d), 1e-9);
    double nearest = std::numeric_limits<double>::infinity();
    for (const auto& p : flat) {
      nearest = std::min(nearest, (origin + p.x() * u + p.y() * v - vertex).norm());
    }
    EXPECT_LT(nearest, options.cell_size) << q.transpose();
  }
}

TEST(PlaneOutline, WideHoleIsNotFilledButSparseSamplingIs) {
  // 10 x 10 m with a 4 x 4 m hole (16 cells wide at 0.25 m, far more than the closing's 2).
  std::vector<Eigen::Vector2d> holed;
  AddGrid(0.0, 10.0, 0.0, 10.0, 0.1, holed, [](const Eigen::Vector2d& p) {
    return p.x() > 3.05 && p.x() < 6.95 && p.y() > 3.05 && p.y() < 6.95;
  });
  const PlaneOutline2d with_hole = ComputePlaneOutline2d(holed, PlaneOutlineOptions());
  // The points stand for 100 m^2 minus a 3.9 x 3.9 m hole.
  EXPECT_NEAR(with_hole.area, 100.0 - 3.9 * 3.9, 2.0);
  EXPECT_LT(with_hole.area, 100.0 - 0.8 * 16.0);
  // The outer ring still encloses the hole (one ring per plane; holes are only in the area).
  EXPECT_GT(PolygonArea2d(with_hole.ring), 90.0);
  // A hole of 3 cells (0.75 m) survives a closing of 1 cell as well.
  std::vector<Eigen::Vector2d> small_hole;
  AddGrid(0.0, 10.0, 0.0, 10.0, 0.1, small_hole, [](const Eigen::Vector2d& p) {
    return p.x() > 4.05 && p.x() < 5.15 && p.y() > 4.05 && p.y() < 5.15;
  });
  const PlaneOutline2d small = ComputePlaneOutline2d(small_hole, PlaneOutlineOptions());
  EXPECT_LT(small.area, 100.0 - 0.5);
  // Sampling sparser than a cell (0.4 m spacing, scan-line like gaps) is closed to the full area.
  std::vector<Eigen::Vector2d> sparse;
  AddGrid(0.0, 10.0, 0.0, 10.0, 0.4, sparse);
  const PlaneOutline2d closed = ComputePlaneOutline2d(sparse, PlaneOutlineOptions());
  EXPECT_NEAR(closed.area, 100.0, 5.0);
  PlaneOutlineOptions no_closing;
  no_closing.closing_cells = 0;
  // Without closing each 0.4 m sample is an isolated cell counted as a quarter of a cell.
  const double unclosed = ComputePlaneOutline2d(sparse, no_closing).area;
  EXPECT_NEAR(unclosed, 26 * 26 * 0.25 * 0.25 * 0.25, 1e-9);
  EXPECT_LT(unclosed, 0.2 * closed.area);
}

TEST(PlaneOutline, PolygonIsTheLargestComponent) {
  std::vector<Eigen::Vector2d> points;
  AddGrid(0.0, 10.0, 0.0, 5.0, 0.1, points);   // 50 m^2
  AddGrid(20.0, 23.0, 0.0, 3.0, 0.1, points);  // 9 m^2, 10 m away
  const PlaneOutline2d outline = ComputePlaneOutline2d(points, PlaneOutlineOptions());
  EXPECT_NEAR(outline.area, 59.0, 0.05 * 59.0);  // all occupied cells count
  for (const auto& q : outline.ring) EXPECT_LT(q.x(), 10.5);
  EXPECT_NEAR(PolygonArea2d(outline.ring), 50.0, 3.0);
}

TEST(PlaneOutline, DeterministicAndOrderIndependent) {
  auto points = LShape();
  const PlaneOutline2d first = ComputePlaneOutline2d(points, PlaneOutlineOptions());
  std::mt19937 rng(7);
  std::shuffle(points.begin(), points.end(), rng);
  const PlaneOutline2d second = ComputePlaneOutline2d(points, PlaneOutlineOptions());
  ASSERT_EQ(first.ring.size(), second.ring.size());
  for (std::size_t i = 0; i < first.ring.size(); ++i) EXPECT_EQ(first.ring[i], second.ring[i]);
  EXPECT_EQ(first.area, second.area);
  EXPECT_TRUE(ComputePlaneOutline2d({}, PlaneOutlineOptions()).ring.empty());
}

TEST(PlaneOutline, OptionsAreChecked) {
  PlaneOutlineOptions options;
  EXPECT_NO_THROW(options.Check());
  options.cell_size = 0.0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = PlaneOutlineOptions();
  options.closing_cells = -1;
  EXPECT_THROW(options.Check(), OptionsError);
  PlaneExtractionOptions extraction;
  extraction.outline.simplify_cells = -1.0;
  EXPECT_THROW(extraction.Check(), OptionsError);
}

}  // namespace
}  // namespace planeloc
