#include "planeloc/io/kitti_calib.h"

#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

std::string Trim(const std::string& text) {
  const auto begin = text.find_first_not_of(" \t\r\n");
  if (begin == std::string::npos) return "";
  const auto end = text.find_last_not_of(" \t\r\n");
  return text.substr(begin, end - begin + 1);
}

// Parses one whitespace-separated token as a finite double; false on junk.
bool ParseFinite(const std::string& token, double* value) {
  try {
    std::size_t used = 0;
    *value = std::stod(token, &used);
    return used == token.size() && std::isfinite(*value);
  } catch (const std::exception&) {
    return false;
  }
}

}  // namespace

KittiCalibFile KittiCalibFile::Read(const std::filesystem::path& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw InputError(path.string(), "calibration file not found",
                     "check the dataset folder; KITTI calibration files come with each sequence "
                     "(odometry: calib.txt, raw: calib_cam_to_cam.txt beside the drive or in its "
                     "date folder)");
  }
  std::ifstream stream(path);
  CheckInput(stream.good(), path.string(), 0, "cannot open the calibration file",
             "check the file permissions");
  KittiCalibFile calib;
  calib.path_ = path;
  std::string line;
  int line_number = 0;
  while (std::getline(stream, line)) {
    ++line_number;
    const std::string trimmed = Trim(line);
    if (trimmed.empty()) continue;
    const auto colon = trimmed.find(':');
    CheckInput(colon != std::string::npos && colon > 0, path.string(), line_number,
               "calibration line has no `key:` prefix",
               "each line must read `KEY: v1 v2 ...` as in the KITTI calibration files");
    const std::string key = Trim(trimmed.substr(0, colon));
    calib.entries_[key] = Entry{trimmed.substr(colon + 1), line_number};
  }
  return calib;
}

int KittiCalibFile::LineOf(const std::string& key) const {
  const auto it = entries_.find(key);
  return it == entries_.end() ? 0 : it->second.line;
}

std::vector<double> KittiCalibFile::Numbers(const std::string& key, std::size_t count) const {
  const auto it = entries_.find(key);
  if (it == entries_.end()) {
    throw InputError(path_.string(), fmt::format("calibration key `{}` is missing", key),
                     fmt::format("add the line `{}: <{} numbers>` (copy it from the original "
                                 "KITTI calibration file)",
                                 key, count));
  }
  std::istringstream tokens(it->second.values);
  std::vector<double> values;
  std::string token;
  while (tokens >> token) {
    double value = 0;
    CheckInput(ParseFinite(token, &value), path_.string(), it->second.line,
               fmt::format("`{}`: value '{}' is not a finite number", key, token),
               "restore the line from the original KITTI calibration file");
    values.push_back(value);
  }
  CheckInput(values.size() == count, path_.string(), it->second.line,
             fmt::format("`{}` has {} numbers, expected {}", key, values.size(), count),
             "restore the line from the original KITTI calibration file (it may be truncated)");
  return values;
}

Matrix3x4d KittiCalibFile::Matrix3x4(const std::string& key) const {
  const std::vector<double> v = Numbers(key, 12);
  Matrix3x4d m;
  for (int i = 0; i < 12; ++i) m(i / 4, i % 4) = v[i];
  return m;
}

Eigen::Matrix3d KittiCalibFile::Matrix3(const std::string& key) const {
  const std::vector<double> v = Numbers(key, 9);
  Eigen::Matrix3d m;
  for (int i = 0; i < 9; ++i) m(i / 3, i % 3) = v[i];
  return m;
}

Eigen::Vector3d KittiCalibFile::Vector3(const std::string& key) const {
  const std::vector<double> v = Numbers(key, 3);
  return Eigen::Vector3d(v[0], v[1], v[2]);
}

Rigid3d KittiCalibFile::ToRigid(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation,
                                const std::string& key) const {
  // KITTI prints 7 significant digits, so R^T R deviates from I by ~1e-6; 1e-3 catches real damage.
  const double orthonormality_error =
      (rotation.transpose() * rotation - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  CheckInput(
      orthonormality_error < 1e-3 && rotation.determinant() > 0, path_.string(), LineOf(key),
      fmt::format("`{}` is not a rotation (|R^T R - I| = {:.2g})", key, orthonormality_error),
      "restore the line from the original KITTI calibration file");
  return Rigid3d(rotation, translation);
}

Rigid3d KittiCalibFile::RigidFromRT(const std::string& r_key, const std::string& t_key) const {
  return ToRigid(Matrix3(r_key), Vector3(t_key), r_key);
}

Rigid3d KittiCalibFile::RigidFrom3x4(const std::string& key) const {
  const Matrix3x4d m = Matrix3x4(key);
  return ToRigid(m.leftCols<3>(), m.col(3), key);
}

Rigid3d RectifiedCameraFromCam0(const Matrix3x4d& projection) {
  return Rigid3d(Eigen::Matrix3d::Identity(),
                 Eigen::Vector3d(projection(0, 3) / projection(0, 0), 0.0, 0.0));
}

StereoCamera StereoCameraFromCalib(const KittiCalibFile& calib, const std::string& left_key,
                                   const std::string& right_key, int width, int height) {
  const Matrix3x4d left = calib.Matrix3x4(left_key);
  const Matrix3x4d right = calib.Matrix3x4(right_key);
  // The pair's own checks below cannot tell which line is wrong; the intrinsics of each can.
  for (const auto& [key, p] : {std::pair{left_key, left}, std::pair{right_key, right}}) {
    if (!(p(0, 0) > 0 && p(1, 1) > 0 && p.allFinite())) {
      throw InputError(calib.path().string(), calib.LineOf(key),
                       fmt::format("`{}` has fx = {} and fy = {}: focal lengths must be positive",
                                   key, p(0, 0), p(1, 1)),
                       "restore the line from the original KITTI calibration");
    }
  }
  try {
    return StereoCamera::FromProjections(left, right, width, height);
  } catch (const std::invalid_argument& error) {
    throw InputError(calib.path().string(), calib.LineOf(right_key),
                     fmt::format("`{}`/`{}` do not form a rectified stereo pair with a positive "
                                 "baseline: {}",
                                 left_key, right_key, error.what()),
                     fmt::format("`{}`(0,3) must equal -fx * baseline relative to `{}`; restore "
                                 "the lines from the original KITTI calibration",
                                 right_key, left_key));
  }
}

KittiOdometryCalib ReadKittiOdometryCalib(const std::filesystem::path& path) {
  const KittiCalibFile file = KittiCalibFile::Read(path);
  KittiOdometryCalib calib;
  for (int k = 0; k < 4; ++k) calib.p[k] = file.Matrix3x4(fmt::format("P{}", k));
  if (file.Has("Tr")) {
    calib.has_cam0_from_velo = true;
    calib.cam0_from_velo = file.RigidFrom3x4("Tr");
  }
  return calib;
}

}  // namespace planeloc
