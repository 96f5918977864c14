#include "planeloc/io/asl_sequence.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>
#include <opencv2/core/eigen.hpp>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "planeloc/io/grey_image.h"
#include "planeloc/io/settings_reader.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/util/error.h"

namespace planeloc {
namespace {

namespace fs = std::filesystem;

bool IsFile(const fs::path& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

std::string Trim(const std::string& text) {
  std::size_t begin = 0, end = text.size();
  while (begin < end && std::isspace(static_cast<unsigned char>(text[begin]))) ++begin;
  while (end > begin && std::isspace(static_cast<unsigned char>(text[end - 1]))) --end;
  return text.substr(begin, end - begin);
}

// data.csv: timestamp (ns) -> image file, in the file's order.
std::vector<std::pair<std::int64_t, fs::path>> ReadImageList(const fs::path& camera) {
  const fs::path csv = camera / "data.csv";
  std::ifstream in(csv);
  CheckInput(in.good(), csv.string(), 0, "the camera's image list is missing",
             "an ASL/EuRoC camera folder holds data.csv (\"#timestamp [ns],filename\") and data/");
  std::vector<std::pair<std::int64_t, fs::path>> images;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    line = Trim(line);
    if (line.empty() || line[0] == '#') continue;
    const std::size_t comma = line.find(',');
    std::int64_t stamp = 0;
    std::size_t used = 0;
    const std::string first = Trim(line.substr(0, comma));
    try {
      stamp = std::stoll(first, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    CheckInput(comma != std::string::npos && used == first.size() && !first.empty() && stamp >= 0,
               csv.string(), number, fmt::format("not \"timestamp [ns],filename\": '{}'", line),
               "each line is an integer timestamp in nanoseconds, a comma and the image's name");
    const std::string file = Trim(line.substr(comma + 1));
    CheckInput(!file.empty(), csv.string(), number, "the line names no image",
               "each line is an integer timestamp in nanoseconds, a comma and the image's name");
    CheckInput(images.empty() || stamp > images.back().first, csv.string(), number,
               fmt::format("timestamp {} does not increase (previous {})", stamp,
                           images.empty() ? 0 : images.back().first),
               "sort the file by timestamp and remove duplicates");
    images.emplace_back(stamp, camera / "data" / file);
  }
  CheckInput(!images.empty(), csv.string(), 0, "the image list is empty",
             "point --sequence at a recorded ASL/EuRoC sequence");
  return images;
}

// A numeric sequence of `node` with `count` entries (count 0: any), else InputError.
std::vector<double> Numbers(const cv::FileNode& node, const std::string& yaml, const char* key,
                            std::size_t count) {
  CheckInput(node.isSeq(), yaml, 0, fmt::format("'{}' is missing or not a list", key),
             "write the EuRoC sensor.yaml fields T_BS, resolution, intrinsics and "
             "distortion_coefficients");
  std::vector<double> values;
  for (const cv::FileNode& item : node) {
    CheckInput(item.isReal() || item.isInt(), yaml, 0, fmt::format("'{}' holds a non-number", key),
               "every entry must be a number");
    values.push_back(static_cast<double>(item));
  }
  CheckInput(count == 0 || values.size() == count, yaml, 0,
             fmt::format("'{}' has {} values, expected {}", key, values.size(), count),
             "see the EuRoC sensor.yaml of cam0");
  return values;
}

struct CameraSensor {
  RawCamera raw;
  cv::Size size;
  Rigid3d body_from_sensor;
};

CameraSensor ReadSensor(const fs::path& camera) {
  const fs::path path = camera / "sensor.yaml";
  const std::string yaml = path.string();
  CheckInput(IsFile(path), yaml, 0, "the camera's calibration is missing",
             "an ASL/EuRoC camera folder holds sensor.yaml (T_BS, intrinsics, distortion)");
  // EuRoC's sensor.yaml starts with a comment, not OpenCV's `%YAML:1.0` header, so the text is
  // normalized first (the settings reader's rules) and parsed from memory.
  std::string text;
  {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream buffer;
    buffer << in.rdbuf();
    CheckInput(in.good() || in.eof(), yaml, 0, "cannot read the file",
               "check the file's permissions");
    text = buffer.str();
  }
  if (const int line = LineOfBadYamlDocumentMarker(text)) {
    throw InputError(yaml, line, "a line starting with `---` that is not a document marker",
                     "write `---` alone on its line (or remove it)");
  }
  NormalizeYamlHeader(text);
  cv::FileStorage storage;
  try {
    storage.open(text,
                 cv::FileStorage::READ | cv::FileStorage::MEMORY | cv::FileStorage::FORMAT_YAML);
  } catch (const std::exception& error) {
    throw InputError(yaml, 0, fmt::format("not readable as YAML: {}", error.what()),
                     "fix the file (see EuRoC's cam0/sensor.yaml)");
  }
  CheckInput(storage.isOpened(), yaml, 0, "not readable as YAML",
             "fix the file (see EuRoC's cam0/sensor.yaml)");
  const std::string model = storage["camera_model"].isString()
                                ? static_cast<std::string>(storage["camera_model"])
                                : std::string("pinhole");
  CheckInput(model == "pinhole", yaml, 0, fmt::format("camera_model '{}' is not supported", model),
             "planeloc reads pinhole cameras with radial-tangential distortion");
  const std::string distortion = storage["distortion_model"].isString()
                                     ? static_cast<std::string>(storage["distortion_model"])
                                     : std::string("radial-tangential");
  CheckInput(distortion == "radial-tangential" || distortion == "radtan", yaml, 0,
             fmt::format("distortion_model '{}' is not supported", distortion),
             "planeloc reads radial-tangential distortion (k1 k2 p1 p2)");

  const std::vector<double> t = Numbers(storage["T_BS"]["data"], yaml, "T_BS.data", 16);
  Eigen::Matrix4d body_from_sensor;
  for (int k = 0; k < 16; ++k) body_from_sensor(k / 4, k % 4) = t[k];
  const Eigen::Matrix3d r = body_from_sensor.topLeftCorner<3, 3>();
  CheckInput((r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-3 &&
                 r.determinant() > 0 &&
                 body_from_sensor.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1)),
             yaml, 0, "T_BS is not a rigid transform (rotation and translation, last row 0 0 0 1)",
             "write T_BS.data as the 16 row-major entries of body_from_sensor");
  const std::vector<double> resolution = Numbers(storage["resolution"], yaml, "resolution", 2);
  const std::vector<double> k = Numbers(storage["intrinsics"], yaml, "intrinsics", 4);
  const std::vector<double> d =
      Numbers(storage["distortion_coefficients"], yaml, "distortion_coefficients", 0);
  CheckInput(d.size() == 4 || d.size() == 5, yaml, 0,
             fmt::format("distortion_coefficients has {} values, expected 4 or 5", d.size()),
             "k1 k2 p1 p2 [k3]");
  CheckInput(resolution[0] >= 1 && resolution[1] >= 1 && k[0] > 0 && k[1] > 0, yaml, 0,
             "resolution and focal lengths must be positive", "see the EuRoC sensor.yaml of cam0");
  CameraSensor sensor;
  sensor.size = cv::Size(static_cast<int>(resolution[0]), static_cast<int>(resolution[1]));
  sensor.raw.k = (cv::Mat_<double>(3, 3) << k[0], 0, k[2], 0, k[1], k[3], 0, 0, 1);
  sensor.raw.d = cv::Mat(d, true).reshape(1, 1);
  sensor.body_from_sensor = Rigid3d::FromMatrix4d(body_from_sensor);
  return sensor;
}

}  // namespace

bool AslSequence::IsAslFolder(const fs::path& folder) {
  return IsFile(folder / "cam0" / "data.csv") || IsFile(folder / "mav0" / "cam0" / "data.csv");
}

AslSequence AslSequence::Open(const fs::path& folder) {
  AslSequence sequence;
  sequence.mav0_ = IsFile(folder / "mav0" / "cam0" / "data.csv") ? folder / "mav0" : folder;
  const fs::path cam0 = sequence.mav0_ / "cam0", cam1 = sequence.mav0_ / "cam1";
  const CameraSensor left = ReadSensor(cam0);
  const CameraSensor right = ReadSensor(cam1);
  CheckInput(left.size == right.size, (cam1 / "sensor.yaml").string(), 0,
             fmt::format("resolution {}x{} differs from cam0's {}x{}", right.size.width,
                         right.size.height, left.size.width, left.size.height),
             "both cameras of the stereo pair must have the same resolution");
  const Rigid3d left_from_right = left.body_from_sensor.Inverse() * right.body_from_sensor;
  cv::Mat extrinsics;
  cv::eigen2cv(Eigen::Matrix4d(left_from_right.Matrix4d()), extrinsics);
  try {
    sequence.rectifier_ = std::make_shared<const StereoRectifier>(
        StereoRectifier::FromExtrinsics(left.raw, right.raw, extrinsics, left.size));
  } catch (const std::exception& error) {
    throw InputError((cam1 / "sensor.yaml").string(), 0,
                     fmt::format("the two cameras do not form a stereo pair: {}", error.what()),
                     "check T_BS of cam0 and cam1 (the right camera must sit beside the left)");
  }
  // The rectified left camera: raw cam0 rotated by the rectification (x_rect = R x_raw).
  Eigen::Matrix3d rect_from_raw;
  cv::cv2eigen(sequence.rectifier_->left_r(), rect_from_raw);
  sequence.body_from_camera_ =
      left.body_from_sensor *
      Rigid3d(Eigen::Matrix3d(rect_from_raw.transpose()), Eigen::Vector3d::Zero());

  const auto left_images = ReadImageList(cam0);
  std::map<std::int64_t, fs::path> right_images;
  for (const auto& [stamp, path] : ReadImageList(cam1)) right_images.emplace(stamp, path);
  for (const auto& [stamp, path] : left_images) {
    const auto right_image = right_images.find(stamp);
    if (right_image == right_images.end()) {
      ++sequence.unpaired_;
      continue;
    }
    sequence.timestamps_ns_.push_back(stamp);
    sequence.left_images_.push_back(path);
    sequence.right_images_.push_back(right_image->second);
  }
  CheckInput(!sequence.timestamps_ns_.empty(), (cam1 / "data.csv").string(), 0,
             "no cam1 image has the timestamp of a cam0 image",
             "the two cameras of an ASL sequence are triggered together: their data.csv files "
             "list the same timestamps");
  if (sequence.unpaired_ > 0) {
    spdlog::warn("{}: {} cam0 images have no cam1 image of the same timestamp; left out",
                 sequence.mav0_.string(), sequence.unpaired_);
  }
  return sequence;
}

Rigid3d AslSequence::CameraPoseFromGroundTruth(const fs::path& csv, std::size_t index) const {
  const Trajectory body = ReadEurocTrajectory(csv);
  const double t = timestamp(index);
  constexpr double kTolerance = 0.01;  // seconds: evo's default association tolerance
  const std::vector<double>& stamps = body.timestamps;
  CheckInput(t >= stamps.front() - kTolerance && t <= stamps.back() + kTolerance, csv.string(), 0,
             fmt::format("frame {} ({:.6f} s) lies outside the ground truth's span ({:.6f} to "
                         "{:.6f} s)",
                         index, t, stamps.front(), stamps.back()),
             "pass the ground truth of this sequence (mav0/state_groundtruth_estimate0/data.csv)");
  const std::size_t after = static_cast<std::size_t>(
      std::clamp<std::ptrdiff_t>(std::upper_bound(stamps.begin(), stamps.end(), t) - stamps.begin(),
                                 1, static_cast<std::ptrdiff_t>(stamps.size()) - 1));
  Rigid3d world_from_body = body.world_from_cam.front();
  if (stamps.size() > 1) {
    const std::size_t before = after - 1;
    const double s = std::clamp((t - stamps[before]) / (stamps[after] - stamps[before]), 0.0, 1.0);
    const Rigid3d& a = body.world_from_cam[before];
    const Rigid3d& b = body.world_from_cam[after];
    world_from_body =
        Rigid3d(a.rotation.slerp(s, b.rotation), (1.0 - s) * a.translation + s * b.translation);
  }
  return world_from_body * body_from_camera_;
}

double AslSequence::timestamp(std::size_t index) const {
  const std::int64_t ns = timestamps_ns_.at(index);
  return static_cast<double>(ns / 1000000000) + static_cast<double>(ns % 1000000000) * 1e-9;
}

bool AslSequence::HasFrame(std::size_t index) const {
  return IsFile(left_images_.at(index)) && IsFile(right_images_.at(index));
}

std::string AslSequence::MissingFrame(std::size_t index) const {
  if (!IsFile(left_images_.at(index))) return left_images_[index].string();
  if (!IsFile(right_images_.at(index))) return right_images_[index].string();
  return "";
}

StereoPair AslSequence::LoadStereoPair(std::size_t index) const {
  const StereoPair raw{LoadGreyImage(left_images_.at(index)),
                       LoadGreyImage(right_images_.at(index))};
  const cv::Size size = rectifier_->size();
  for (const auto& [image, path] :
       {std::pair{&raw.left, &left_images_[index]}, std::pair{&raw.right, &right_images_[index]}}) {
    CheckInput(image->size() == size, path->string(), 0,
               fmt::format("image is {}x{} but sensor.yaml says {}x{}", image->cols, image->rows,
                           size.width, size.height),
               "the images must have the resolution of their sensor.yaml");
  }
  return rectifier_->Rectify(raw);
}

}  // namespace planeloc
