#include "planeloc/tracking/plane_association.h"

#include <gtest/gtest.h>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

MapPlane MakePlane(int id, const Plane& plane, std::vector<Eigen::Vector3d> polygon, double area) {
  MapPlane p;
  p.id = id;
  p.plane_in_map = plane;
  p.polygon = std::move(polygon);
  p.area = area;
  return p;
}

// KITTI camera world: y down. Road y = 1.65 over x in [-5, 6], z in [0, 40]; a facade x = 6 over
// y in [-6, 1.65], z in [0, 40]; a 2 m^2 sign; plane ids are not positions.
PlaneMap Street() {
  PlaneMap map;
  map.planes.push_back(MakePlane(10, Plane(Eigen::Vector3d(0, -1, 0), 1.65),
                                 {{-5, 1.65, 0}, {6, 1.65, 0}, {6, 1.65, 40}, {-5, 1.65, 40}},
                                 400));
  map.planes.push_back(MakePlane(3, Plane(Eigen::Vector3d(1, 0, 0), -6.0),
                                 {{6, -6, 0}, {6, 1.65, 0}, {6, 1.65, 40}, {6, -6, 40}}, 306));
  map.planes.push_back(MakePlane(7, Plane(Eigen::Vector3d(0, 0, 1), -20.0),
                                 {{0, 0, 20}, {1, 0, 20}, {1, 2, 20}, {0, 2, 20}}, 2));
  return map;
}

TEST(PlaneAssociationTest, PointsOnPlanesInsideTheirOutlines) {
  const PlaneAssociator planes(Street(), PlaneAssociationOptions());
  EXPECT_EQ(planes.size(), 2u);                                 // the sign is below min_plane_area
  EXPECT_EQ(planes.Associate({0, 1.60, 10}), 10);               // 5 cm above the road
  EXPECT_EQ(planes.Associate({6.1, -2, 30}), 3);                // 10 cm in front of the facade
  EXPECT_EQ(planes.Associate({0, 1.40, 10}), std::nullopt);     // 25 cm above the road
  EXPECT_EQ(planes.Associate({-5.3, 1.65, 10}), 10);            // within the 0.5 m margin
  EXPECT_EQ(planes.Associate({-6.0, 1.65, 10}), std::nullopt);  // beyond it
  EXPECT_EQ(planes.Associate({0, 1.65, 60}), std::nullopt);     // on the infinite plane only
  EXPECT_EQ(planes.Associate({0.5, 1, 20}), std::nullopt);      // the unused sign
  // In the crease the road and the facade both claim the point: none.
  EXPECT_EQ(planes.Associate({5.95, 1.6, 10}), std::nullopt);
  EXPECT_EQ(planes.Associate({std::nan(""), 0, 0}), std::nullopt);
  EXPECT_EQ(planes.plane(3).id, 3);
  EXPECT_THROW(planes.plane(7), std::out_of_range);
}

TEST(PlaneAssociationTest, FarFromTheOriginAndWithoutOutline) {
  // A map kilometres from its origin, and a plane given without polygon (unbounded).
  PlaneMap map;
  const Eigen::Vector3d offset(3000, 0, -2500);
  std::vector<Eigen::Vector3d> ring = {{-5, 1.65, 0}, {5, 1.65, 0}, {5, 1.65, 40}, {-5, 1.65, 40}};
  for (auto& p : ring) p += offset;
  map.planes.push_back(MakePlane(0, Plane(Eigen::Vector3d(0, -1, 0), 1.65), ring, 400));
  map.planes.push_back(MakePlane(1, Plane(Eigen::Vector3d(0, 0, 1), 100.0), {}, 0));
  const PlaneAssociator planes(map, PlaneAssociationOptions());
  EXPECT_EQ(planes.Associate(offset + Eigen::Vector3d(0, 1.6, 20)), 0);
  EXPECT_EQ(planes.Associate({12345, -7, -100.05}), 1);
}

TEST(PlaneAssociationTest, OptionsCheck) {
  PlaneAssociationOptions options;
  options.max_distance = 0;
  EXPECT_THROW(options.Check(), OptionsError);
  options = PlaneAssociationOptions();
  options.cell_size = -1;
  EXPECT_THROW(PlaneAssociator(PlaneMap(), options), OptionsError);
}

}  // namespace
}  // namespace planeloc
