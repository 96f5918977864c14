#include "planeloc/prior/map_lock.h"

#include <gtest/gtest.h>

#include <map>
#include <string>
#include <utility>
#include <vector>

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

// A finished attempt that found no lock, as the registration reports one.
RegistrationJob Refused(const std::string& reason, int keyframe_id) {
  RegistrationJob job;
  job.keyframe_id = keyframe_id;
  RegistrationResult result;
  result.lock = MapLock::kSearching;
  result.reason = reason;
  job.result = result;
  return job;
}

TEST(MapLockerTest, CountsWhyTheAttemptsBeforeTheLockChangedNothing) {
  MapLocker locker(Street(false), MapLockOptions{}, Gnss(2.0), Rigid3d{});
  for (const auto& [reason, id] :
       std::vector<std::pair<std::string, int>>{{"few points on planes (12 of 300)", 2},
                                                {"the planes in view do not constrain roll", 4},
                                                {"few points on planes (40 of 410)", 6}}) {
    const auto finished = locker.Finish(Refused(reason, id));
    ASSERT_TRUE(finished.has_value());
    EXPECT_FALSE(finished->first.applied);
  }
  EXPECT_EQ(locker.state(), MapLock::kSearching);
  EXPECT_EQ(locker.attempts_before_lock(), 3);
  const std::map<std::string, int> expected = {{"few points on planes", 2},
                                               {"the planes in view do not constrain roll", 1}};
  EXPECT_EQ(locker.refusals(), expected);
  // An exact start is locked from the start: nothing to count.
  MapLocker exact(Street(false), MapLockOptions{}, StartPrior{}, Rigid3d{});
  exact.Finish(Refused("few points on planes (1 of 2)", 2));
  EXPECT_EQ(exact.attempts_before_lock(), 0);
  EXPECT_TRUE(exact.refusals().empty());
}

TEST(MapLockerTest, ReasonCategoriesLeaveOutTheNumbers) {
  EXPECT_EQ(ReasonCategory("too little structure (80 points, need 150)"), "too little structure");
  EXPECT_EQ(ReasonCategory("refused: 3.4 sigma from the current estimate in lateral (limit 3.0)"),
            "refused: beyond the gate in lateral");
  EXPECT_EQ(ReasonCategory("ambiguous: a distinct hypothesis fits almost as well"),
            "ambiguous: a distinct hypothesis fits almost as well");
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
