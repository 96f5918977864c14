#include "planeloc/map/fast_exp.h"

#include <gtest/gtest.h>

#include <cmath>

namespace planeloc {
namespace {

TEST(FastExpTest, MatchesStdExpAndIsZeroFarOut) {
  double worst = 0.0, worst_near = 0.0;
  for (float x = 0.0f; x < 86.0f; x += 0.001953125f) {  // 2^-9 steps: crosses every binade
    const double expected = std::exp(-static_cast<double>(x));
    const double error = std::abs(FastNegExp(x) - expected) / expected;
    worst = std::max(worst, error);
    if (x < 20.0f) worst_near = std::max(worst_near, error);
  }
  EXPECT_LT(worst, 1e-5);
  EXPECT_LT(worst_near, 2e-6);
  EXPECT_EQ(FastNegExp(0.0f), 1.0f);
  EXPECT_EQ(FastNegExp(-3.0f), 1.0f);  // clamped: the decays never see x < 0
  EXPECT_EQ(FastNegExp(87.0f), 0.0f);
  EXPECT_EQ(FastNegExp(1e30f), 0.0f);
  EXPECT_EQ(FastNegExp(INFINITY), 0.0f);
}

}  // namespace
}  // namespace planeloc
