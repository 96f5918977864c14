#include "planeloc/map/plane_map_eval.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

MapPlane Rectangle(int id, const std::string& kind, const Plane& plane,
                   std::vector<Eigen::Vector3d> polygon) {
  MapPlane p;
  p.id = id;
  p.kind = kind;
  p.plane_in_map = plane;
  p.polygon = std::move(polygon);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& v : p.polygon) sum += v;
  p.centroid = sum / static_cast<double>(p.polygon.size());
  return p;
}

// Ground z = 0 over x in [0, 10], y in [0, 10] (100 m^2) and a second, coplanar ground piece over
// x in [20, 30] that the map sees only 10 m^2 of; 0.1 m grid points.
struct Fixture {
  PlaneMap gt;
  std::vector<Eigen::Vector3d> points;
  Fixture() {
    const Plane z0{Eigen::Vector3d::UnitZ(), 0.0};
    gt.planes.push_back(
        Rectangle(0, "ground", z0, {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}}));
    gt.planes.push_back(
        Rectangle(1, "ground", z0, {{20, 0, 0}, {30, 0, 0}, {30, 10, 0}, {20, 10, 0}}));
    gt.planes.push_back(Rectangle(2, "other", Plane{Eigen::Vector3d::UnitX(), -5.0}, {}));
    for (double x = 0.05; x < 10; x += 0.1) {
      for (double y = 0.05; y < 10; y += 0.1) points.emplace_back(x, y, 0.0);
    }
    for (double x = 20.05; x < 30; x += 0.1) {
      for (double y = 0.05; y < 1; y += 0.1) points.emplace_back(x, y, 0.0);
    }
    points.emplace_back(5.5, 5, 3.0);  // clutter, 0.5 m off the x = 5 plane
  }
};

TEST(PlaneMapEvalTest, MatchesBySupportAndMeasuresAngleAndOffset) {
  const Fixture f;
  // Extracted: plane 7 = the ground tilted by 0.5 deg about y through (5, 5, 0.02), labelling
  // the first piece; plane 3 = a perfect copy that labels nothing of it.
  const double tilt = 0.5 * std::numbers::pi / 180.0;
  const Eigen::Vector3d n(std::sin(tilt), 0.0, std::cos(tilt));
  PlaneMap extracted;
  MapPlane good = Rectangle(7, "ground", Plane::FromPointAndNormal({5, 5, 0.02}, n),
                            {{0, 0, 0}, {10, 0, 0}, {10, 10, 0}, {0, 10, 0}});
  good.centroid = {5, 5, 0.02};
  extracted.planes.push_back(good);
  extracted.planes.push_back(
      Rectangle(3, "ground", Plane{Eigen::Vector3d::UnitZ(), 0.0}, {{40, 0, 0}, {41, 1, 0}}));
  std::vector<int> labels(f.points.size(), -1);
  for (std::size_t i = 0; i < 10000; ++i) labels[i] = i % 10 == 0 ? -1 : 7;  // 90 % support
  labels.back() = 7;  // the clutter point, >= 0.5 m off every GT plane

  PlaneMapEvalOptions options;
  const PlaneMapEvaluation evaluation =
      EvaluatePlaneMap(f.points, labels, extracted, f.gt, options);
  // Plane 1 is seen on 10 m^2 < 20 m^2 and plane 2 is of another kind: only plane 0 is checked.
  ASSERT_EQ(evaluation.checked.size(), 1u);
  const GtPlaneMatch& m = evaluation.checked[0];
  EXPECT_EQ(m.gt_id, 0);
  EXPECT_NEAR(m.visible_area, 100.0, 1e-9);
  EXPECT_EQ(m.extracted_id, 7);  // by support, although plane 3 is the better-looking plane
  EXPECT_NEAR(m.support, 0.9, 1e-9);
  EXPECT_NEAR(m.angle_deg, 0.5, 1e-9);
  EXPECT_NEAR(m.offset, 0.02, 1e-12);
  EXPECT_TRUE(m.good);
  EXPECT_TRUE(evaluation.AllGood());
  EXPECT_EQ(evaluation.labelled_points, 9001u);
  EXPECT_NEAR(evaluation.labelled_on_gt, 9000.0 / 9001.0, 1e-12);
  const nlohmann::json json = evaluation.ToJson();
  EXPECT_EQ(json["checked"], 1);
  EXPECT_EQ(json["planes"][0]["extracted_id"], 7);

  // Tighter tolerances turn the same match bad; a lower area threshold checks plane 1, which no
  // extracted plane supports.
  options.max_angle_deg = 0.4;
  options.min_visible_area = 5.0;
  const PlaneMapEvaluation strict = EvaluatePlaneMap(f.points, labels, extracted, f.gt, options);
  ASSERT_EQ(strict.checked.size(), 2u);
  EXPECT_FALSE(strict.checked[0].good);
  EXPECT_EQ(strict.checked[1].gt_id, 1);
  EXPECT_NEAR(strict.checked[1].visible_area, 10.0, 1e-9);
  EXPECT_EQ(strict.checked[1].extracted_id, -1);
  EXPECT_FALSE(strict.checked[1].good);
  EXPECT_EQ(strict.good, 0);
}

TEST(PlaneMapEvalTest, RejectsBadInput) {
  const Fixture f;
  EXPECT_THROW(EvaluatePlaneMap(f.points, {}, PlaneMap(), f.gt, PlaneMapEvalOptions()),
               std::invalid_argument);
  PlaneMapEvalOptions options;
  options.point_area = 0.0;
  EXPECT_THROW(options.Check(), OptionsError);
}

}  // namespace
}  // namespace planeloc
