#include "planeloc/util/error.h"

#include <gtest/gtest.h>

namespace planeloc {
namespace {

TEST(InputError, MessageNamesFileLineAndFix) {
  const InputError error("calib.txt", 3, "P1 has 11 numbers, expected 12", "check the file");
  EXPECT_STREQ(error.what(), "calib.txt:3: P1 has 11 numbers, expected 12 (fix: check the file)");
  EXPECT_EQ(error.path(), "calib.txt");
  EXPECT_EQ(error.line(), 3);
}

TEST(InputError, MessageWithoutLine) {
  const InputError error("map.pcd", "map has no points", "");
  EXPECT_STREQ(error.what(), "map.pcd: map has no points");
}

TEST(InputError, CheckInputThrowsOnlyWhenFalse) {
  EXPECT_NO_THROW(CheckInput(true, "a", 1, "b", "c"));
  EXPECT_THROW(CheckInput(false, "a", 1, "b", "c"), InputError);
}

}  // namespace
}  // namespace planeloc
