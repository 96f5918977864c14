#include "planeloc/prior/map_lock.h"

#include <gtest/gtest.h>

#include "planeloc/prior/street_for_test.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

using namespace street_for_test;  // NOLINT(build/namespaces): the fixture

StartPrior Gnss(double horizontal) {
  StartPrior prior;
  prior.sigma_horizontal = horizontal;
  prior.sigma_vertical = 0.5;
  prior.sigma_yaw_deg = 5.0;
  return prior;
}

TEST(StartPriorWarningTest, AStartInTheMapIsQuiet) {
  EXPECT_EQ(StartPriorWarning(Street(false), {0, 0, 10}, Gnss(2.0)), "");
}

TEST(StartPriorWarningTest, AStartFarFromEveryPlaneNamesTheFlagAndTheMap) {
  // The street spans x in [-7, 7], z in [-10, 70]: 300 m away, beyond 3 * 2.06 m + 20 m.
  PlaneMap street = Street(false);
  street.source = "planes.json";
  const std::string warning = StartPriorWarning(street, {0, 0, 370}, Gnss(2.0));
  EXPECT_NE(warning.find("planes.json"), std::string::npos) << warning;
  EXPECT_NE(warning.find("--init-sigma"), std::string::npos) << warning;
  EXPECT_NE(warning.find("300 m"), std::string::npos) << warning;
}

TEST(StartPriorWarningTest, APriorWiderThanTheMapWarns) {
  // 3 * 10 m = 30 m against a street of 80 m: quiet; a 14 m x 14 m square of planes: warns.
  EXPECT_EQ(StartPriorWarning(Street(false), {0, 0, 10}, Gnss(10.0)), "");
  PlaneMap square;
  square.planes.push_back(MakePlane(0, Plane(Eigen::Vector3d(0, -1, 0), 1.65),
                                    {{-7, 1.65, -7}, {7, 1.65, -7}, {7, 1.65, 7}, {-7, 1.65, 7}},
                                    "ground"));
  const std::string warning = StartPriorWarning(square, {0, 0, 0}, Gnss(10.0));
  EXPECT_NE(warning.find("wider than the map (14 m across)"), std::string::npos) << warning;
}

TEST(StartPriorWarningTest, AnExactStartNeverWarns) {
  EXPECT_EQ(StartPriorWarning(Street(false), {0, 0, 370}, StartPrior()), "");
}

TEST(StartPriorTest, SigmasBeyondTheSearchRangeAreRefused) {
  EXPECT_NO_THROW(Gnss(10.0).Check());
  EXPECT_THROW(Gnss(10.5).Check(), OptionsError);
  StartPrior tall = Gnss(2.0);
  tall.sigma_vertical = 1e6;  // took 1 GB for 12 frames before the bound
  EXPECT_THROW(tall.Check(), OptionsError);
  StartPrior turned = Gnss(2.0);
  turned.sigma_yaw_deg = 16.0;
  EXPECT_THROW(turned.Check(), OptionsError);
}

}  // namespace
}  // namespace planeloc
