// libFuzzer target: pose files (KITTI 12 numbers a line, TUM `t x y z qx qy qz qw`) and times.txt.
// Every reader gets the same bytes. An InputError is the reader's answer to bad input; anything
// else is a finding. See scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>

#include "planeloc/io/trajectory.h"
#include "planeloc/util/error.h"
#include "planeloc/util/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace planeloc;
  const auto path = WriteFuzzInput(data, size, ".txt");
  auto attempt = [](auto&& read) {
    try {
      read();
    } catch (const InputError&) {
    }
  };
  attempt([&] { ReadKittiTrajectory(path).PathLength(); });
  attempt([&] { ReadKittiPoseMatrices(path); });
  attempt([&] { ReadTumTrajectory(path).PathLength(); });
  attempt([&] { ReadTimestamps(path); });
  return 0;
}
