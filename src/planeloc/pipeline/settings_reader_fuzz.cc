// libFuzzer target: tracker settings files (OpenCV FileStorage YAML, ORB-SLAM2/3 layouts), read
// as `run --config` reads them. An InputError is the reader's answer to bad input; anything else
// is a finding. See scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>

#include "planeloc/pipeline/settings.h"
#include "planeloc/util/error.h"
#include "planeloc/util/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace planeloc;
  const auto path = WriteFuzzInput(data, size, ".yaml");
  try {
    LoadTrackerSettings(path, TrackerOptions{});
  } catch (const InputError&) {
  }
  return 0;
}
