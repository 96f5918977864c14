// Checks of command-line values in the user's words: the flag, the value given, what is allowed
// and a fix ("--voxel -1: expected a size in metres >= 0 ..."), never the name of an internal
// options field or a range of 309 digits. The library's Options::Check() stays the last guard.
#pragma once

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "planeloc/util/error.h"

namespace planeloc::cli {

// Throws InputError("--flag VALUE: expected EXPECTED", fix) unless `valid`.
template <typename T>
void CheckFlag(bool valid, const std::string& flag, const T& value, const std::string& expected,
               const std::string& fix) {
  if (!valid) {
    throw InputError("", 0, fmt::format("{} {}: expected {}", flag, value, expected), fix);
  }
}

// A finite number >= low.
inline bool AtLeast(double value, double low) { return std::isfinite(value) && value >= low; }

}  // namespace planeloc::cli
