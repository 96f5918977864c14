// Locating the real KITTI data in ../shared/data for tests.
//
// The data lives beside the project checkout, never inside it. A test that needs it calls
// PLANELOC_REQUIRE_SHARED_DATA_OR_SKIP(path) first: when the data is missing the test is skipped
// with a message, except when the environment sets PLANELOC_REQUIRE_SHARED_DATA=1 (CI does), where
// it fails.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace planeloc::testing {

// Root of the shared data: $PLANELOC_SHARED_DATA if set, else <source>/../shared/data.
inline std::filesystem::path SharedDataDir() {
  if (const char* env = std::getenv("PLANELOC_SHARED_DATA")) return env;
#ifdef PLANELOC_SOURCE_DIR
  return std::filesystem::path(PLANELOC_SOURCE_DIR) / ".." / "shared" / "data";
#else
  return std::filesystem::path("..") / "shared" / "data";
#endif
}

inline bool SharedDataRequired() {
  const char* env = std::getenv("PLANELOC_REQUIRE_SHARED_DATA");
  return env != nullptr && std::string(env) == "1";
}

}  // namespace planeloc::testing

// `relative` is a path below the shared data root; binds `var` to the full path.
#define PLANELOC_SHARED_DATA_OR_SKIP(var, relative)                                                \
  const std::filesystem::path var = ::planeloc::testing::SharedDataDir() / (relative);             \
  do {                                                                                             \
    if (!std::filesystem::exists(var)) {                                                           \
      if (::planeloc::testing::SharedDataRequired()) {                                             \
        FAIL() << "shared data missing: " << var                                                   \
               << " (PLANELOC_REQUIRE_SHARED_DATA=1; put the KITTI data in ../shared/data)";       \
      }                                                                                            \
      GTEST_SKIP() << "shared data not found at " << var                                           \
                   << "; set PLANELOC_SHARED_DATA or place it in ../shared/data to run this test"; \
    }                                                                                              \
  } while (0)
