// libFuzzer target: plane maps (planes.json). An InputError is the reader's answer to bad input;
// anything else is a finding. See scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>

#include "planeloc/io/plane_map.h"
#include "planeloc/util/error.h"
#include "planeloc/util/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace planeloc;
  const auto path = WriteFuzzInput(data, size, ".json");
  try {
    ReadPlaneMap(path);
  } catch (const InputError&) {
  }
  return 0;
}
