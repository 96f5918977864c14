// Writers of the simulator's ASL / EuRoC MAV layout (the other output beside sim_output.h's KITTI
// layout): mav0/camX/{sensor.yaml,data.csv,data/<ns>.png} and
// mav0/state_groundtruth_estimate0/data.csv, read back by planeloc::AslSequence and
// ReadEurocTrajectory. Numbers are written at full precision (shortest round trip), so what is
// read back is what was written. Every file is whole (util/safe_file.h): complete or absent.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "planeloc/geometry/rigid3.h"

namespace planeloc::sim {

// One camera of an ASL rig as EuRoC's sensor.yaml describes it.
struct AslCamera {
  Rigid3d body_from_sensor;  // T_BS
  int width = 752, height = 480;
  double fu = 0.0, fv = 0.0, cu = 0.0, cv = 0.0;         // pinhole intrinsics, pixels
  Eigen::Vector4d distortion = Eigen::Vector4d::Zero();  // radial-tangential k1 k2 p1 p2
  double rate_hz = 20.0;
};

// EuRoC's VI-Sensor with the calibration published in the sensor.yaml of every MH/V1/V2
// sequence. T_BS goes through Rigid3d's quaternion, so the written matrix is the published one
// re-orthonormalized (entries differ by 3e-13 at most).
AslCamera EurocCam0();
AslCamera EurocCam1();

// Writes `path` (a camera's sensor.yaml) in EuRoC's form, with the "%YAML:1.0" first line that
// cv::FileStorage (and so AslSequence) needs and EuRoC's own files lack. InputError (naming
// `path`) when the camera is not one AslSequence would read: no size or focal length.
void WriteAslCameraYaml(const std::filesystem::path& path, const AslCamera& camera,
                        const std::string& comment);

// A camera's data.csv: "#timestamp [ns],filename", then "<ns>,<ns>.png" a frame, with LF line
// ends as kitti_to_asl.py writes them (AslSequence takes LF and CRLF alike). InputError when the
// stamps are empty, negative or not strictly increasing (AslSequence would reject the file).
void WriteAslImageList(const std::filesystem::path& path,
                       const std::vector<std::int64_t>& stamps_ns);
// "<ns>.png": the image's name under camX/data/.
std::string AslImageName(std::int64_t stamp_ns);

// state_groundtruth_estimate0/data.csv with EuRoC's 17 columns: the body pose world_from_body at
// each stamp (quaternion w x y z with w >= 0), the velocity in the world frame by central
// differences of the positions (one-sided at the two ends, zero for a single pose) and zero gyro
// and accelerometer biases. InputError when the sizes differ or the stamps are empty, negative or
// not strictly increasing.
void WriteAslGroundTruth(const std::filesystem::path& path,
                         const std::vector<std::int64_t>& stamps_ns,
                         const std::vector<Rigid3d>& world_from_body);

}  // namespace planeloc::sim
