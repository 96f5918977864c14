// libFuzzer target: PCL .pcd point clouds (ascii, binary, binary_compressed), read as
// `map planes` does, without and with a voxel filter. An InputError is the reader's answer to bad
// input; anything else is a finding. See scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>

#include "planeloc/io/point_cloud.h"
#include "planeloc/util/error.h"
#include "planeloc/util/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace planeloc;
  const auto path = WriteFuzzInput(data, size, ".pcd");
  for (const double voxel : {0.0, 0.25}) {
    try {
      ReadPointCloud(path, {.voxel_size = voxel});
    } catch (const InputError&) {
      return 0;  // the same bytes fail the same way with the voxel filter
    }
  }
  return 0;
}
