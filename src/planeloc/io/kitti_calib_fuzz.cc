// libFuzzer target: KITTI calibration files (odometry calib.txt and the raw calib_*.txt keys).
// An InputError is the reader's answer to bad input; anything else (a crash, a sanitizer report,
// another exception, a hang, a huge allocation) is a finding. See scripts/fuzz.sh.
#include <cstddef>
#include <cstdint>

#include "planeloc/io/kitti_calib.h"
#include "planeloc/util/error.h"
#include "planeloc/util/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace planeloc;
  const auto path = WriteFuzzInput(data, size, ".txt");
  try {
    ReadKittiOdometryCalib(path);
  } catch (const InputError&) {
  }
  try {
    const KittiCalibFile calib = KittiCalibFile::Read(path);
    // The raw-dataset accessors, each on its own: a bad key must not hide the next one.
    auto attempt = [](auto&& read) {
      try {
        read();
      } catch (const InputError&) {
      }
    };
    attempt([&] { calib.RigidFromRT("R", "T"); });
    attempt([&] { calib.RigidFromRT("R_rect_00", "T_00"); });
    attempt([&] { StereoCameraFromCalib(calib, "P_rect_02", "P_rect_03", 1242, 375); });
    attempt([&] { StereoCameraFromCalib(calib, "P0", "P1", 1241, 376); });
    attempt([&] { calib.Numbers("S_rect_02", 2); });
    attempt([&] { calib.Vector3("T"); });
  } catch (const InputError&) {
  }
  return 0;
}
