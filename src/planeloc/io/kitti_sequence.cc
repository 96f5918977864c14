#include "planeloc/io/kitti_sequence.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "planeloc/io/grey_image.h"
#include "planeloc/io/kitti_calib.h"
#include "planeloc/io/oxts.h"
#include "planeloc/io/trajectory.h"
#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

namespace planeloc {
namespace fs = std::filesystem;
namespace {

bool IsDirectory(const fs::path& path) {
  std::error_code error;
  return fs::is_directory(path, error);
}

bool IsFile(const fs::path& path) {
  std::error_code error;
  return fs::is_regular_file(path, error);
}

// Files of `directory` ending in `extension`, sorted by name (KITTI names are zero-padded).
std::vector<fs::path> ListFiles(const fs::path& directory, const std::string& extension) {
  std::vector<fs::path> files;
  std::error_code error;
  fs::directory_iterator iterator(directory, error);
  CheckInput(!error, directory.string(), 0, "cannot list the folder: " + error.message(),
             "check that the folder exists and is readable");
  for (const fs::directory_entry& entry : iterator) {
    if (entry.is_regular_file() && entry.path().extension() == extension) {
      files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

// Image size from the PNG header (IHDR), so Open() decodes no image; other formats are decoded.
cv::Size ReadImageSize(const fs::path& path) {
  std::ifstream stream(path, std::ios::binary);
  CheckInput(stream.good(), path.string(), 0, "image file missing or unreadable",
             "check the image folder of the sequence");
  unsigned char header[24] = {};
  stream.read(reinterpret_cast<char*>(header), sizeof(header));
  static constexpr unsigned char kPngSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (stream.gcount() == sizeof(header) && std::equal(kPngSignature, kPngSignature + 8, header) &&
      std::equal(header + 12, header + 16, "IHDR")) {
    auto big_endian = [&](int offset) {
      return static_cast<int>((std::uint32_t{header[offset]} << 24) |
                              (std::uint32_t{header[offset + 1]} << 16) |
                              (std::uint32_t{header[offset + 2]} << 8) | header[offset + 3]);
    };
    const cv::Size size(big_endian(16), big_endian(20));
    if (size.width > 0 && size.height > 0) return size;
  }
  const cv::Mat image = cv::imread(path.string(), cv::IMREAD_GRAYSCALE);
  CheckInput(!image.empty(), path.string(), 0, "image does not decode",
             "the file is corrupt or not an image; re-extract it from the KITTI archive");
  return image.size();
}

// Days since 1970-01-01 of a proleptic Gregorian date (H. Hinnant's days_from_civil).
std::int64_t DaysFromCivil(std::int64_t year, unsigned month, unsigned day) {
  year -= month <= 2;
  const std::int64_t era = (year >= 0 ? year : year - 399) / 400;
  const unsigned year_of_era = static_cast<unsigned>(year - era * 400);
  const unsigned day_of_year = (153 * (month + (month > 2 ? -3 : 9)) + 2) / 5 + day - 1;
  const unsigned day_of_era = year_of_era * 365 + year_of_era / 4 - year_of_era / 100 + day_of_year;
  return era * 146097 + static_cast<std::int64_t>(day_of_era) - 719468;
}

// `2011-09-26 13:02:25.964389445` -> integer nanoseconds since 1970 (exact: doubles would lose the
// nanoseconds of a 1.3e9 s epoch time).
bool ParseDateTimeNanoseconds(const std::string& text, std::int64_t* nanoseconds) {
  int year = 0, month = 0, day = 0, hour = 0, minute = 0, second = 0, used = 0;
  if (std::sscanf(text.c_str(), "%d-%d-%d %d:%d:%d%n", &year, &month, &day, &hour, &minute, &second,
                  &used) != 6 ||
      month < 1 || month > 12 || day < 1 || day > 31 || hour < 0 || hour > 23 || minute < 0 ||
      minute > 59 || second < 0 || second > 60) {
    return false;
  }
  std::string rest = text.substr(used);
  while (!rest.empty() && std::isspace(static_cast<unsigned char>(rest.back()))) rest.pop_back();
  std::int64_t fraction = 0;
  if (!rest.empty()) {
    if (rest[0] != '.' || rest.size() < 2 || rest.size() > 10) return false;
    std::string digits = rest.substr(1);
    if (!std::all_of(digits.begin(), digits.end(),
                     [](unsigned char c) { return std::isdigit(c) != 0; })) {
      return false;
    }
    digits.resize(9, '0');
    fraction = std::stoll(digits);
  }
  const std::int64_t seconds = DaysFromCivil(year, month, day) * 86400 + std::int64_t{hour} * 3600 +
                               std::int64_t{minute} * 60 + second;
  *nanoseconds = seconds * 1'000'000'000 + fraction;
  return true;
}

// Frame times must increase strictly: equal or decreasing times would end up in TUM output and
// break the motion model's time steps.
void CheckIncreasing(const std::vector<double>& seconds, double next, const fs::path& path,
                     int line) {
  if (seconds.empty() || next > seconds.back()) return;
  throw InputError(
      path.string(), line,
      fmt::format("time {:.9g} s is not after the previous frame's {:.9g} s", next, seconds.back()),
      "frame times must increase strictly (one line per frame, in order); restore "
      "the file from the dataset");
}

const char* kCountFix =
    "the sequence must have one line per frame; re-extract it, or remove the extra images";

std::vector<double> ReadRawTimestamps(const fs::path& path, std::size_t expected) {
  std::ifstream stream(path);
  CheckInput(stream.good(), path.string(), 0, "timestamps file missing or unreadable",
             "each KITTI raw camera folder has a timestamps.txt; re-extract the drive");
  std::vector<double> seconds;
  std::int64_t first = 0;
  std::string line;
  int line_number = 0;
  while (std::getline(stream, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::int64_t nanoseconds = 0;
    CheckInput(ParseDateTimeNanoseconds(line, &nanoseconds), path.string(), line_number,
               fmt::format("'{}' is not a date-time like 2011-09-26 13:02:25.964389445", line),
               "restore the file from the KITTI raw drive");
    if (seconds.empty()) first = nanoseconds;
    CheckIncreasing(seconds, static_cast<double>(nanoseconds - first) * 1e-9, path, line_number);
    seconds.push_back(static_cast<double>(nanoseconds - first) * 1e-9);
  }
  CheckInput(seconds.size() == expected, path.string(), 0,
             fmt::format("{} timestamps for {} frames", seconds.size(), expected), kCountFix);
  return seconds;
}

std::vector<double> ReadOdometryTimes(const fs::path& path, std::size_t expected) {
  std::ifstream stream(path);
  CheckInput(stream.good(), path.string(), 0, "times.txt missing or unreadable",
             "a KITTI odometry sequence has times.txt beside calib.txt (data_odometry_calib)");
  std::vector<double> seconds;
  std::string line;
  int line_number = 0;
  while (std::getline(stream, line)) {
    ++line_number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    double value = 0;
    std::size_t used = 0;
    try {
      value = std::stod(line, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    CheckInput(used > 0 && std::isfinite(value) &&
                   line.find_first_not_of(" \t\r", used) == std::string::npos,
               path.string(), line_number, fmt::format("'{}' is not a time in seconds", line),
               "one number (seconds) per line");
    CheckIncreasing(seconds, value, path, line_number);
    seconds.push_back(value);
  }
  CheckInput(seconds.size() == expected, path.string(), 0,
             fmt::format("{} times for {} frames", seconds.size(), expected), kCountFix);
  return seconds;
}

// Re-expresses cam0 poses as poses of a camera rigidly attached by cam_from_cam0, rebased so that
// the first pose is the identity.
std::vector<Rigid3d> RebaseAndConjugate(const std::vector<Rigid3d>& world_from_cam0,
                                        const Rigid3d& cam_from_cam0) {
  const Rigid3d cam0_from_world0 = world_from_cam0.front().Inverse();
  std::vector<Rigid3d> out;
  out.reserve(world_from_cam0.size());
  for (const Rigid3d& pose : world_from_cam0) {
    out.push_back(cam_from_cam0 * cam0_from_world0 * pose * cam_from_cam0.Inverse());
  }
  return out;
}

// Looks for a calibration file in the drive folder, then in its parent (the date folder).
std::optional<fs::path> FindBesideOrAbove(const fs::path& folder, const std::string& name) {
  for (const fs::path& candidate : {folder / name, folder.parent_path() / name}) {
    if (IsFile(candidate)) return candidate;
  }
  return std::nullopt;
}

}  // namespace

CameraChoice ParseCameraChoice(const std::string& name) {
  if (name == "auto") return CameraChoice::kAuto;
  if (name == "grey" || name == "gray") return CameraChoice::kGrey;
  if (name == "color" || name == "colour") return CameraChoice::kColor;
  throw InputError("", fmt::format("unknown camera choice '{}'", name),
                   "use auto, grey (image_0/1, image_00/01) or color (image_2/3, image_02/03)");
}

KittiSequence KittiSequence::Open(const fs::path& folder, CameraChoice cameras) {
  KittiSequence sequence;
  fs::path normal = fs::absolute(folder).lexically_normal();
  if (!normal.has_filename()) normal = normal.parent_path();
  sequence.folder_ = normal;
  CheckInput(IsDirectory(normal), folder.string(), 0, "dataset folder not found",
             "pass a KITTI odometry sequence (sequences/XX) or a raw drive folder "
             "(YYYY_MM_DD_drive_NNNN_sync)");
  const bool raw =
      IsDirectory(normal / "image_00" / "data") || IsDirectory(normal / "image_02" / "data");
  const bool odometry = IsFile(normal / "calib.txt") || IsDirectory(normal / "image_0") ||
                        IsDirectory(normal / "image_2");
  CheckInput(raw || odometry, normal.string(), 0,
             "not a KITTI sequence: neither image_00/data, image_02/data (raw) nor calib.txt, "
             "image_0, image_2 (odometry) found",
             "pass a KITTI odometry sequence (sequences/XX) or a raw drive folder");
  if (raw) {
    sequence.OpenRaw(cameras);
  } else {
    sequence.OpenOdometry(cameras);
  }
  return sequence;
}

bool KittiSequence::ChooseColour(CameraChoice cameras, const fs::path& grey_left,
                                 const fs::path& colour_left) const {
  const bool has_grey = IsDirectory(grey_left);
  const bool has_colour = IsDirectory(colour_left);
  switch (cameras) {
    case CameraChoice::kGrey:
      CheckInput(has_grey, grey_left.string(), 0, "grey camera folder not found",
                 "use --cameras color (or auto) for a sequence with colour images only");
      return false;
    case CameraChoice::kColor:
      CheckInput(has_colour, colour_left.string(), 0, "colour camera folder not found",
                 "use --cameras grey (or auto) for a sequence with grey images only");
      return true;
    case CameraChoice::kAuto:
      break;
  }
  if (has_grey) return false;
  CheckInput(has_colour, folder_.string(), 0, "neither grey nor colour images found",
             "the sequence needs image_0/image_1 (or image_00/01/data), or the colour pair");
  return true;
}

namespace {

// KITTI numbers frames with fixed-width decimal file names (000042.png, 0000000042.png). When every
// name of both cameras is such a number, returns the width; else 0.
int NumericNameWidth(const std::vector<fs::path>& left, const std::vector<fs::path>& right) {
  int width = 0;
  for (const auto* files : {&left, &right}) {
    for (const fs::path& file : *files) {
      const std::string stem = file.stem().string();
      if (stem.empty() || (width != 0 && static_cast<int>(stem.size()) != width) ||
          !std::all_of(stem.begin(), stem.end(),
                       [](unsigned char c) { return std::isdigit(c) != 0; })) {
        return 0;
      }
      width = static_cast<int>(stem.size());
    }
  }
  return width;
}

}  // namespace

void KittiSequence::ListFrames(const fs::path& left_dir, const fs::path& right_dir) {
  CheckInput(IsDirectory(right_dir), right_dir.string(), 0, "right camera folder not found",
             "a stereo sequence needs both cameras of the pair; re-extract the sequence");
  const std::vector<fs::path> left_files = ListFiles(left_dir, ".png");
  const std::vector<fs::path> right_files = ListFiles(right_dir, ".png");
  CheckInput(!left_files.empty(), left_dir.string(), 0, "no .png images",
             "re-extract the sequence's images");
  // Frames are the union of both cameras' file names; with KITTI's numbered names, every number
  // from 0 to the last one, so a frame missing in both cameras is a gap too. A frame with a
  // missing image stays in the list (HasFrame() is false for it) and is skipped by the tracker.
  std::vector<std::string> names;
  if (const int width = NumericNameWidth(left_files, right_files); width > 0) {
    const long last = std::max(std::stol(left_files.back().stem().string()),
                               right_files.empty() ? 0L : std::stol(right_files.back().stem()));
    for (long frame = 0; frame <= last; ++frame) {
      names.push_back(fmt::format("{:0{}d}.png", frame, width));
    }
  } else {
    for (const auto* files : {&left_files, &right_files}) {
      for (const fs::path& file : *files) names.push_back(file.filename().string());
    }
    std::sort(names.begin(), names.end());
    names.erase(std::unique(names.begin(), names.end()), names.end());
  }
  left_images_.clear();
  right_images_.clear();
  std::vector<std::string> missing;
  std::size_t missing_left = 0, missing_right = 0;
  for (const std::string& name : names) {
    left_images_.push_back(left_dir / name);
    right_images_.push_back(right_dir / name);
    const bool has_left = IsFile(left_images_.back());
    const bool has_right = IsFile(right_images_.back());
    missing_left += !has_left;
    missing_right += !has_right;
    if (!has_left || !has_right) {
      missing.push_back(fmt::format("{} ({})", name,
                                    !has_left && !has_right ? "both"
                                    : has_left              ? "right"
                                                            : "left"));
    }
  }
  for (const fs::path& first : {left_images_.front(), right_images_.front()}) {
    CheckInput(IsFile(first), first.string(), 0,
               fmt::format("the first frame's {} image is missing",
                           first == left_images_.front() ? "left" : "right"),
               "the first frame sets the image size, the initial pose and the scale; restore it "
               "or start the sequence at the next frame");
  }
  // Many missing images are not gaps but two cameras that do not belong together.
  CheckInput(2 * std::max(missing_left, missing_right) <= names.size(), right_dir.string(), 0,
             fmt::format("{} left images in {} and {} right images here for {} frames",
                         left_files.size(), left_dir.string(), right_files.size(), names.size()),
             "both cameras need one image per frame with the same frame numbers; re-extract the "
             "missing ones");
  if (!missing.empty()) {
    const std::size_t shown = std::min<std::size_t>(missing.size(), 5);
    std::string list;
    for (std::size_t i = 0; i < shown; ++i) list += (i ? ", " : "") + missing[i];
    spdlog::warn("{}: {} of {} frames miss an image and will be skipped: {}{}",
                 left_dir.parent_path().string(), missing.size(), names.size(), list,
                 missing.size() > shown ? ", ..." : "");
  }
}

void KittiSequence::SetCameraFromCalib(const KittiCalibFile& calib, const std::string& left_key,
                                       const std::string& right_key) {
  camera_calibration_path_ = calib.path();
  const cv::Size size = ReadImageSize(left_images_.front());
  const cv::Size right_size = ReadImageSize(right_images_.front());
  CheckInput(right_size == size, right_images_.front().string(), 0,
             fmt::format("the first frame's right image is {}x{} but its left image {} is {}x{}",
                         right_size.width, right_size.height, left_images_.front().string(),
                         size.width, size.height),
             "both cameras of a rectified pair must have the same image size; re-extract them");
  camera_ = StereoCameraFromCalib(calib, left_key, right_key, size.width, size.height);
}

void KittiSequence::SetVelodyneScans(const fs::path& velodyne_dir) {
  velodyne_scans_.assign(left_images_.size(), std::nullopt);
  if (!IsDirectory(velodyne_dir)) return;
  for (std::size_t i = 0; i < left_images_.size(); ++i) {
    fs::path scan = velodyne_dir / left_images_[i].filename();
    scan.replace_extension(".bin");
    if (IsFile(scan)) velodyne_scans_[i] = scan;
  }
}

void KittiSequence::OpenOdometry(CameraChoice cameras) {
  layout_ = KittiLayout::kOdometry;
  const bool colour = ChooseColour(cameras, folder_ / "image_0", folder_ / "image_2");
  ListFrames(folder_ / (colour ? "image_2" : "image_0"),
             folder_ / (colour ? "image_3" : "image_1"));
  const KittiCalibFile calib = KittiCalibFile::Read(folder_ / "calib.txt");
  const std::string left_key = colour ? "P2" : "P0";
  SetCameraFromCalib(calib, left_key, colour ? "P3" : "P1");
  timestamps_ = ReadOdometryTimes(folder_ / "times.txt", left_images_.size());
  SetVelodyneScans(folder_ / "velodyne");
  // Tr and poses/XX.txt refer to cam0; the colour camera sits at P2's x offset from it.
  const Rigid3d cam_from_cam0 = RectifiedCameraFromCam0(calib.Matrix3x4(left_key));
  velo_calibration_path_ = folder_ / "calib.txt";
  if (calib.Has("Tr")) cam_from_velo_ = cam_from_cam0 * calib.RigidFrom3x4("Tr");
  const fs::path poses_path =
      folder_.parent_path().parent_path() / "poses" / (folder_.filename().string() + ".txt");
  if (IsFile(poses_path)) {
    const std::vector<Rigid3d> world_from_cam0 = ReadKittiTrajectory(poses_path).world_from_cam;
    CheckInput(world_from_cam0.size() == size(), poses_path.string(), 0,
               fmt::format("{} poses for {} frames", world_from_cam0.size(), size()),
               "the ground truth must have one pose per frame of the sequence");
    ground_truth_ = RebaseAndConjugate(world_from_cam0, cam_from_cam0);
  }
}

void KittiSequence::OpenRaw(CameraChoice cameras) {
  layout_ = KittiLayout::kRaw;
  const bool colour =
      ChooseColour(cameras, folder_ / "image_00" / "data", folder_ / "image_02" / "data");
  const std::string left = colour ? "02" : "00";
  const std::string right = colour ? "03" : "01";
  ListFrames(folder_ / ("image_" + left) / "data", folder_ / ("image_" + right) / "data");
  const std::optional<fs::path> cam_to_cam = FindBesideOrAbove(folder_, "calib_cam_to_cam.txt");
  CheckInput(cam_to_cam.has_value(), (folder_ / "calib_cam_to_cam.txt").string(), 0,
             "calibration file not found here nor in the parent (date) folder",
             "copy calib_cam_to_cam.txt of the drive's date (KITTI raw calibration zip) beside "
             "the drive");
  const KittiCalibFile calib = KittiCalibFile::Read(*cam_to_cam);
  SetCameraFromCalib(calib, "P_rect_" + left, "P_rect_" + right);
  timestamps_ =
      ReadRawTimestamps(folder_ / ("image_" + left) / "timestamps.txt", left_images_.size());
  SetVelodyneScans(folder_ / "velodyne_points" / "data");

  // Rectified camera k: x_cam = offset_k + R_rect_00 * (R x_velo + T) (KITTI raw devkit).
  const std::optional<fs::path> velo_to_cam = FindBesideOrAbove(folder_, "calib_velo_to_cam.txt");
  velo_calibration_path_ = velo_to_cam.value_or(folder_ / "calib_velo_to_cam.txt");
  if (velo_to_cam) {
    const KittiCalibFile velo = KittiCalibFile::Read(*velo_to_cam);
    const Rigid3d rect0_from_cam0(calib.Matrix3("R_rect_00"), Eigen::Vector3d::Zero());
    cam_from_velo_ = RectifiedCameraFromCam0(calib.Matrix3x4("P_rect_" + left)) * rect0_from_cam0 *
                     velo.RigidFromRT("R", "T");
  }
  LoadOxtsGroundTruth();
}

const Rigid3d& KittiSequence::RequireCamFromVelo() const {
  if (cam_from_velo_) return *cam_from_velo_;
  if (layout_ == KittiLayout::kOdometry) {
    throw InputError(velo_calibration_path_.string(), 0,
                     "no `Tr` line: the LiDAR-to-camera calibration that the scans need",
                     "add the sequence's `Tr:` line (12 numbers, KITTI odometry's calib.txt)");
  }
  throw InputError(velo_calibration_path_.string(), 0,
                   "the LiDAR-to-camera calibration was not found here nor in the parent (date) "
                   "folder",
                   "copy calib_velo_to_cam.txt of the drive's date (KITTI raw calibration zip) "
                   "beside the drive");
}

void KittiSequence::LoadOxtsGroundTruth() {
  const fs::path oxts_dir = folder_ / "oxts" / "data";
  if (!IsDirectory(oxts_dir)) return;
  const std::vector<fs::path> files = ListFiles(oxts_dir, ".txt");
  CheckInput(files.size() == size(), oxts_dir.string(), 0,
             fmt::format("{} OXTS packets for {} frames", files.size(), size()),
             "the synced drive has one packet per frame; re-extract oxts/ or delete it to load "
             "the drive without ground truth");
  const std::optional<fs::path> imu_to_velo = FindBesideOrAbove(folder_, "calib_imu_to_velo.txt");
  const std::string missing_fix =
      "copy the drive date's calibration files beside the drive, or delete oxts/ to load it "
      "without ground truth";
  CheckInput(imu_to_velo.has_value(), (folder_ / "calib_imu_to_velo.txt").string(), 0,
             "OXTS ground truth needs this calibration file", missing_fix);
  CheckInput(cam_from_velo_.has_value(), (folder_ / "calib_velo_to_cam.txt").string(), 0,
             "OXTS ground truth needs this calibration file", missing_fix);
  const Rigid3d velo_from_imu = KittiCalibFile::Read(*imu_to_velo).RigidFromRT("R", "T");
  std::vector<OxtsPacket> packets;
  packets.reserve(files.size());
  for (const fs::path& file : files) packets.push_back(ReadOxtsPacket(file));
  ground_truth_ = ImuPosesToCameraPoses(OxtsToImuPoses(packets), *cam_from_velo_ * velo_from_imu);
}

fs::path KittiSequence::left_image_path(std::size_t index) const { return left_images_.at(index); }

fs::path KittiSequence::right_image_path(std::size_t index) const {
  return right_images_.at(index);
}

bool KittiSequence::HasFrame(std::size_t index) const {
  return IsFile(left_images_.at(index)) && IsFile(right_images_.at(index));
}

std::string KittiSequence::MissingFrame(std::size_t index) const {
  if (!IsFile(left_images_.at(index))) return left_images_[index].string();
  if (!IsFile(right_images_.at(index))) return right_images_[index].string();
  return "";
}

StereoPair KittiSequence::LoadStereoPair(std::size_t index) const {
  StereoPair pair{LoadGreyImage(left_images_.at(index)), LoadGreyImage(right_images_.at(index))};
  CheckInput(
      pair.left.size() == pair.right.size(), right_images_[index].string(), 0,
      fmt::format("right image is {}x{} but left image {} is {}x{}", pair.right.cols,
                  pair.right.rows, left_images_[index].string(), pair.left.cols, pair.left.rows),
      "both images of a rectified pair must have the same size; re-extract them");
  CheckInput(pair.left.cols == camera_.width && pair.left.rows == camera_.height,
             left_images_[index].string(), 0,
             fmt::format("image is {}x{} but the sequence's first image is {}x{}", pair.left.cols,
                         pair.left.rows, camera_.width, camera_.height),
             "all frames of a sequence must have the same size; re-extract the image");
  return pair;
}

std::optional<fs::path> KittiSequence::velodyne_path(std::size_t index) const {
  return velodyne_scans_.at(index);
}

VelodyneScan ReadVelodyneScan(const fs::path& path) {
  std::error_code error;
  const auto bytes = fs::file_size(path, error);
  CheckInput(!error && IsFile(path), path.string(), 0, "Velodyne scan missing or unreadable",
             "check the velodyne folder of the sequence");
  CheckInput(bytes % 16 == 0, path.string(), 0,
             fmt::format("file size {} bytes is not a multiple of 16 (float32 x, y, z, "
                         "reflectance per point)",
                         bytes),
             "the scan is truncated or not a KITTI .bin; re-extract it");
  std::vector<float> raw(bytes / sizeof(float));
  std::ifstream stream(path, std::ios::binary);
  stream.read(reinterpret_cast<char*>(raw.data()), static_cast<std::streamsize>(bytes));
  CheckInput(stream.gcount() == static_cast<std::streamsize>(bytes), path.string(), 0,
             "could not read the whole scan", "check the file");
  VelodyneScan scan;
  const std::size_t count = raw.size() / 4;
  scan.points.reserve(count);
  scan.reflectance.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    scan.points.emplace_back(raw[4 * i], raw[4 * i + 1], raw[4 * i + 2]);
    scan.reflectance.push_back(raw[4 * i + 3]);
  }
  return scan;
}

void WriteVelodyneScan(const fs::path& path, const VelodyneScan& scan) {
  if (!scan.reflectance.empty() && scan.reflectance.size() != scan.points.size()) {
    throw std::invalid_argument("WriteVelodyneScan: reflectance and points differ in length");
  }
  std::vector<float> raw;
  raw.reserve(4 * scan.points.size());
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    const Eigen::Vector3f point = scan.points[i].cast<float>();
    raw.insert(raw.end(), {point.x(), point.y(), point.z(),
                           scan.reflectance.empty() ? 0.0f : scan.reflectance[i]});
  }
  WriteFileWhole(path, std::string_view(reinterpret_cast<const char*>(raw.data()),
                                        raw.size() * sizeof(float)));
}

}  // namespace planeloc
