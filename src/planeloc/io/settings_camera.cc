#include "planeloc/io/settings_camera.h"

#include <fmt/format.h>

#include <cmath>

#include "planeloc/util/error.h"

namespace planeloc {
namespace {

constexpr const char* kRectifyFix =
    "planeloc needs rectified pinhole stereo pairs, or radial-tangential pinhole cameras it can "
    "rectify on load (LEFT/RIGHT K, D, R, P, or ORB-SLAM3 Camera.type \"PinHole\" with Camera2.* "
    "and Stereo.T_c1_c2): rectify fisheye images beforehand and describe the rectified camera";

[[noreturn]] void Refuse(const SettingsReader& reader, const std::string& key,
                         const std::string& what) {
  throw InputError(reader.path().string(), reader.LineOf(key), what, kRectifyFix);
}

// Reads `keys` as numbers; true when all are zero (or absent).
bool ZeroDistortion(SettingsReader& reader, const std::string& prefix,
                    const std::vector<std::string>& keys) {
  bool zero = true;
  for (const auto& k : keys) {
    const std::optional<double> value = reader.Number(prefix + k);
    if (value && *value != 0.0) zero = false;
  }
  return zero;
}

int FirstLine(const SettingsReader& reader, const std::string& prefix) {
  for (const char* k : {"fx", "fy", "cx", "cy"}) {
    if (reader.LineOf(prefix + k) > 0) return reader.LineOf(prefix + k);
  }
  return 0;
}

// fx, fy, cx, cy under `prefix` ("Camera." or "Camera1."); false unless all four are numbers.
// Some but not all of them is an error.
bool ReadIntrinsics(SettingsReader& reader, const std::string& prefix, SettingsCamera& camera) {
  const std::optional<double> fx = reader.Number(prefix + "fx"), fy = reader.Number(prefix + "fy"),
                              cx = reader.Number(prefix + "cx"), cy = reader.Number(prefix + "cy");
  const int given = reader.Has(prefix + "fx") + reader.Has(prefix + "fy") +
                    reader.Has(prefix + "cx") + reader.Has(prefix + "cy");
  if (given == 0) return false;
  for (const char* k : {"fx", "fy", "cx", "cy"}) {
    if (!reader.Has(prefix + k)) {
      reader.AddProblem(
          FirstLine(reader, prefix),
          fmt::format("{}{} is missing: {}fx, fy, cx and cy go together", prefix, k, prefix));
    }
  }
  if (!fx || !fy || !cx || !cy) return false;
  if (*fx <= 0) reader.AddError(prefix + "fx", "a focal length > 0 (pixels)");
  if (*fy <= 0) reader.AddError(prefix + "fy", "a focal length > 0 (pixels)");
  if (*fx <= 0 || *fy <= 0) return false;
  camera.fx = *fx;
  camera.fy = *fy;
  camera.cx = *cx;
  camera.cy = *cy;
  camera.fx_key = prefix + "fx";
  camera.fy_key = prefix + "fy";
  camera.cx_key = prefix + "cx";
  camera.cy_key = prefix + "cy";
  camera.line = reader.LineOf(prefix + "fx");
  return true;
}

// Fuzzing finding: Camera.height 3 700 912 made the rectification maps 18 GB. No camera sold
// has a side above 16 384 pixels; a number beyond it is a typo, not an image.
constexpr int kMaxImageSide = 16384;
constexpr const char* kImageSideRule = "an image side of 1 to 16384 pixels";
bool PlausibleImageSide(int pixels) { return pixels > 0 && pixels <= kMaxImageSide; }

void ReadImageSize(SettingsReader& reader, SettingsCamera& camera) {
  const std::optional<int> width = reader.Integer("Camera.width");
  const std::optional<int> height = reader.Integer("Camera.height");
  if (width && !PlausibleImageSide(*width)) {
    reader.AddError("Camera.width", kImageSideRule);
  }
  if (height && !PlausibleImageSide(*height)) {
    reader.AddError("Camera.height", kImageSideRule);
  }
  camera.width = width.value_or(0);
  camera.height = height.value_or(0);
  // ORB-SLAM3 resizes every image to Camera.newWidth x newHeight; planeloc does not.
  for (const auto& [key, size] : {std::pair<std::string, int>{"Camera.newWidth", camera.width},
                                  {"Camera.newHeight", camera.height}}) {
    const std::optional<int> value = reader.Integer(key);
    if (value && *value != size) {
      throw InputError(
          reader.path().string(), reader.LineOf(key),
          fmt::format("{} = {} asks for resized images, which planeloc does not do", key, *value),
          "resize the images (and scale calib.txt) beforehand, or remove "
          "Camera.newWidth/newHeight");
    }
  }
}

void RefuseFisheye(SettingsReader& reader) {
  const std::optional<std::string> type = reader.String("Camera.type");
  if (type && *type == "KannalaBrandt8") {
    Refuse(reader, "Camera.type",
           "Camera.type \"KannalaBrandt8\" is a fisheye camera; planeloc needs rectified pinhole "
           "stereo");
  }
  const std::optional<bool> fisheye = reader.Flag("Camera.bFishEye");
  if (fisheye && *fisheye) {
    Refuse(reader, "Camera.bFishEye",
           "Camera.bFishEye = 1: planeloc needs rectified pinhole stereo");
  }
}

// The raw camera `prefix` ("LEFT." / "RIGHT.") of an ORB-SLAM2 EuRoC-style file.
struct RawSide {
  RawCamera camera;
  cv::Mat r, p;
  cv::Size size;
};

std::optional<RawSide> ReadRawSide(SettingsReader& reader, const std::string& prefix) {
  RawSide side;
  const auto k = reader.Matrix(prefix + "K", 3, 3);
  const auto d = reader.Matrix(prefix + "D", -1, -1);
  const auto r = reader.Matrix(prefix + "R", 3, 3);
  const auto p = reader.Matrix(prefix + "P", 3, 4);
  const auto width = reader.Integer(prefix + "width");
  const auto height = reader.Integer(prefix + "height");
  for (const char* key : {"K", "D", "R", "P", "width", "height"}) {
    if (!reader.Has(prefix + key)) {
      reader.AddProblem(reader.LineOf(prefix + "K"),
                        fmt::format("{}{} is missing: a raw stereo pair needs LEFT. and RIGHT. "
                                    "K, D, R, P, width and height",
                                    prefix, key));
    }
  }
  if (d && d->total() != 4 && d->total() != 5) {
    reader.AddError(prefix + "D", "4 or 5 distortion values (k1, k2, p1, p2[, k3])");
  }
  if (width && !PlausibleImageSide(*width)) reader.AddError(prefix + "width", kImageSideRule);
  if (height && !PlausibleImageSide(*height)) reader.AddError(prefix + "height", kImageSideRule);
  if (!k || !d || !r || !p || !width || !height || reader.HasErrors()) return std::nullopt;
  side.camera = {*k, d->reshape(1, 1)};
  side.r = *r;
  side.p = *p;
  side.size = cv::Size(*width, *height);
  return side;
}

// Builds the rectifier of an ORB-SLAM2 LEFT/RIGHT rig; the camera becomes LEFT.P / RIGHT.P.
// `compare`: the file also gives Camera.fx/fy/cx/cy/bf, which should equal LEFT.P/RIGHT.P.
std::optional<SettingsCamera> RawOrbSlam2Rig(SettingsReader& reader, SettingsCamera camera,
                                             bool compare, std::vector<std::string>* warnings) {
  const std::optional<RawSide> left = ReadRawSide(reader, "LEFT.");
  const std::optional<RawSide> right = ReadRawSide(reader, "RIGHT.");
  if (!left || !right) return std::nullopt;
  if (left->size != right->size) {
    reader.AddProblem(reader.LineOf("RIGHT.width"),
                      "LEFT.width/height and RIGHT.width/height differ");
    return std::nullopt;
  }
  try {
    camera.rectifier = std::make_shared<StereoRectifier>(StereoRectifier::FromRectification(
        left->camera, left->r, left->p, right->camera, right->r, right->p, left->size));
  } catch (const std::invalid_argument& e) {
    throw InputError(
        reader.path().string(), reader.LineOf("RIGHT.P"),
        std::string("LEFT/RIGHT do not describe a rectifiable stereo pair: ") + e.what(),
        "give LEFT.P and RIGHT.P of one rectification (same fx, cx; RIGHT.P(0,3) = "
        "-fx * baseline)");
  }
  const StereoCamera& rectified = camera.rectifier->camera();
  if (camera.line == 0) camera.line = reader.LineOf("LEFT.P");
  if (compare &&
      (std::abs(rectified.fx - camera.fx) > 0.5 || std::abs(rectified.cx - camera.cx) > 0.5 ||
       std::abs(rectified.cy - camera.cy) > 0.5 ||
       std::abs(rectified.baseline - camera.baseline) > 0.005 * rectified.baseline)) {
    warnings->push_back(fmt::format(
        "line {}: Camera.fx/cx/cy/bf ({}, {}, {}, {}) differ from LEFT.P/RIGHT.P ({}, {}, {}, "
        "{}); LEFT.P/RIGHT.P are used",
        camera.line, camera.fx, camera.cx, camera.cy, camera.baseline * camera.fx, rectified.fx,
        rectified.cx, rectified.cy, rectified.BaselineTimesFx()));
  }
  camera.fx = rectified.fx;
  camera.fy = rectified.fy;
  camera.cx = rectified.cx;
  camera.cy = rectified.cy;
  camera.baseline = rectified.baseline;
  camera.width = left->size.width;
  camera.height = left->size.height;
  camera.fx_key = camera.fy_key = camera.cx_key = camera.cy_key = "LEFT.P";
  camera.baseline_key = "RIGHT.P";
  return camera;
}

std::optional<SettingsCamera> ReadOrbSlam2(SettingsReader& reader,
                                           std::vector<std::string>* warnings) {
  const std::optional<std::string> type = reader.String("Camera.type");
  if (type && *type != "PinHole" && *type != "Rectified") {
    reader.AddError("Camera.type", "\"PinHole\" or \"Rectified\"");
  }
  SettingsCamera camera;
  camera.layout = "ORB-SLAM2";
  const bool has_intrinsics = ReadIntrinsics(reader, "Camera.", camera);
  const std::optional<double> bf = reader.Number("Camera.bf");
  if (!ZeroDistortion(reader, "Camera.", {"k1", "k2", "p1", "p2", "k3"})) {
    warnings->push_back(
        "Camera.k1/k2/p1/p2/k3 are not zero but ignored: planeloc treats the images as "
        "rectified (no distortion)");
  }
  ReadImageSize(reader, camera);
  // LEFT/RIGHT alone define the (rectified) camera; Camera.* is then only compared with them.
  const bool raw_rig = reader.HasPrefix("LEFT.") || reader.HasPrefix("RIGHT.");
  if (!has_intrinsics && !bf && !raw_rig) return std::nullopt;
  if (has_intrinsics != bf.has_value() && !reader.HasErrors()) {
    reader.AddProblem(reader.LineOf(bf ? "Camera.bf" : "Camera.fx"),
                      "Camera.fx, fy, cx, cy and Camera.bf go together");
    return std::nullopt;
  }
  if (bf && *bf <= 0) {
    reader.AddError("Camera.bf", "baseline x fx > 0 (metres x pixels)");
    return std::nullopt;
  }
  if (has_intrinsics && bf) {
    camera.baseline = *bf / camera.fx;
    camera.baseline_key = "Camera.bf";
  }
  if (raw_rig) return RawOrbSlam2Rig(reader, camera, has_intrinsics && bf, warnings);
  return camera;
}

RawCamera PinHoleCamera(SettingsReader& reader, const SettingsCamera& c,
                        const std::string& prefix) {
  RawCamera camera;
  camera.k = (cv::Mat_<double>(3, 3) << c.fx, 0, c.cx, 0, c.fy, c.cy, 0, 0, 1);
  std::vector<double> d;
  for (const char* k : {"k1", "k2", "p1", "p2", "k3"}) {
    if (reader.Has(prefix + k) || std::string(k) != "k3") {
      d.push_back(reader.Number(prefix + k).value_or(0.0));
    }
  }
  camera.d = cv::Mat(d, true).reshape(1, 1);
  return camera;
}

// A PinHole pair (Camera2, Stereo.T_c1_c2): returns the baseline when the pair is rectified
// already; otherwise sets `raw_reasons` (why it is not) and `rectifier`.
double PinHoleBaseline(SettingsReader& reader, const SettingsCamera& left,
                       std::string* raw_reasons) {
  SettingsCamera right;
  const bool has_right = ReadIntrinsics(reader, "Camera2.", right);
  std::optional<cv::Mat> c1_from_c2;
  if (reader.Has("Stereo.T_c1_c2")) c1_from_c2 = reader.Matrix("Stereo.T_c1_c2", 4, 4);
  const std::vector<std::string> distortion = {"k1", "k2", "p1", "p2", "k3"};
  const bool zero1 = ZeroDistortion(reader, "Camera1.", distortion);
  const bool zero2 = ZeroDistortion(reader, "Camera2.", distortion);
  if (reader.HasErrors()) return 0.0;
  if (!has_right || !c1_from_c2) {
    reader.AddProblem(left.line,
                      "Camera.type \"PinHole\" stereo needs Camera2.fx/fy/cx/cy and "
                      "Stereo.T_c1_c2 (or use Camera.type \"Rectified\" with Stereo.b)");
    return 0.0;
  }
  auto same = [](double a, double b) {
    return std::abs(a - b) <= 1e-6 * std::max(1.0, std::abs(a));
  };
  const cv::Mat& t = *c1_from_c2;
  const bool same_intrinsics = same(left.fx, right.fx) && same(left.fy, right.fy) &&
                               same(left.cx, right.cx) && same(left.cy, right.cy);
  const bool identity_rotation =
      cv::norm(t(cv::Rect(0, 0, 3, 3)), cv::Mat::eye(3, 3, CV_64F), cv::NORM_INF) <= 1e-6;
  const bool along_x = std::abs(t.at<double>(1, 3)) <= 1e-6 &&
                       std::abs(t.at<double>(2, 3)) <= 1e-6 && t.at<double>(0, 3) > 0;
  std::string reasons;
  auto reason = [&](bool bad, const char* what) {
    if (bad) reasons.append(reasons.empty() ? "" : ", ").append(what);
  };
  reason(!zero1 || !zero2, "distortion");
  reason(!same_intrinsics, "different intrinsics");
  reason(!identity_rotation, "a rotation between the cameras");
  reason(!along_x, "a translation not along +x");
  if (!reasons.empty()) {
    *raw_reasons = reasons;
    return 0.0;
  }
  return t.at<double>(0, 3);
}

// Builds the rectifier of an unrectified ORB-SLAM3 PinHole pair (cv::stereoRectify).
std::optional<SettingsCamera> RawOrbSlam3Rig(SettingsReader& reader, SettingsCamera camera,
                                             const std::string& reasons,
                                             std::vector<std::string>* warnings) {
  if (camera.width <= 0 || camera.height <= 0) {
    reader.AddProblem(camera.line,
                      "Camera.width and Camera.height are needed to rectify the PinHole pair");
    return std::nullopt;
  }
  SettingsCamera right;
  ReadIntrinsics(reader, "Camera2.", right);
  const RawCamera left_raw = PinHoleCamera(reader, camera, "Camera1.");
  const RawCamera right_raw = PinHoleCamera(reader, right, "Camera2.");
  const cv::Mat c1_from_c2 = *reader.Matrix("Stereo.T_c1_c2", 4, 4);
  try {
    camera.rectifier = std::make_shared<StereoRectifier>(StereoRectifier::FromExtrinsics(
        left_raw, right_raw, c1_from_c2, cv::Size(camera.width, camera.height)));
  } catch (const std::exception& e) {
    throw InputError(reader.path().string(), reader.LineOf("Stereo.T_c1_c2"),
                     std::string("cannot rectify the PinHole pair: ") + e.what(),
                     "check Camera1.*, Camera2.* and Stereo.T_c1_c2 (c1_from_c2, metres)");
  }
  const StereoCamera& rectified = camera.rectifier->camera();
  warnings->push_back(fmt::format(
      "line {}: the PinHole pair is not rectified ({}): rectifying every frame on load, "
      "rectified fx {:.3f}, cx {:.3f}, cy {:.3f}, baseline {:.5f} m",
      reader.LineOf("Stereo.T_c1_c2"), reasons, rectified.fx, rectified.cx, rectified.cy,
      rectified.baseline));
  camera.fx = rectified.fx;
  camera.fy = rectified.fy;
  camera.cx = rectified.cx;
  camera.cy = rectified.cy;
  camera.baseline = rectified.baseline;
  return camera;
}

std::optional<SettingsCamera> ReadOrbSlam3(SettingsReader& reader,
                                           std::vector<std::string>* warnings) {
  const std::optional<std::string> version = reader.String("File.version");
  if (version && *version != "1.0") {
    warnings->push_back(fmt::format(
        "line {}: File.version \"{}\": planeloc knows ORB-SLAM3's layout \"1.0\"; reading it as "
        "such",
        reader.LineOf("File.version"), *version));
  }
  const std::optional<std::string> type = reader.String("Camera.type");
  SettingsCamera camera;
  camera.layout = "ORB-SLAM3";
  const bool has_intrinsics = ReadIntrinsics(reader, "Camera1.", camera);
  ReadImageSize(reader, camera);
  if (!type) {
    if (!reader.Has("Camera.type")) {
      reader.AddProblem(camera.line,
                        "Camera.type is missing: expected \"Rectified\" or \"PinHole\" with "
                        "Camera1.*");
    }
    return std::nullopt;
  }
  if (*type != "Rectified" && *type != "PinHole") {
    reader.AddError("Camera.type", "\"Rectified\" or \"PinHole\"");
    return std::nullopt;
  }
  if (!has_intrinsics) return std::nullopt;
  const std::optional<double> b = reader.Number("Stereo.b");
  if (b && *b <= 0) reader.AddError("Stereo.b", "a baseline > 0 (metres)");
  if (*type == "PinHole" && (reader.HasPrefix("Camera2.") || reader.Has("Stereo.T_c1_c2"))) {
    std::string raw_reasons;
    camera.baseline = PinHoleBaseline(reader, camera, &raw_reasons);
    camera.baseline_key = "Stereo.T_c1_c2";
    if (!raw_reasons.empty()) return RawOrbSlam3Rig(reader, camera, raw_reasons, warnings);
    if (b && std::abs(*b - camera.baseline) > 0.005 * camera.baseline) {
      warnings->push_back(
          fmt::format("line {}: Stereo.b = {} differs from the translation of Stereo.T_c1_c2 ({}); "
                      "Stereo.T_c1_c2 is used, as ORB-SLAM3 does",
                      reader.LineOf("Stereo.b"), *b, camera.baseline));
    }
    return !reader.HasErrors() ? std::optional<SettingsCamera>(camera) : std::nullopt;
  }
  if (*type == "PinHole" && !ZeroDistortion(reader, "Camera1.", {"k1", "k2", "p1", "p2", "k3"})) {
    warnings->push_back(
        "Camera1.k1/k2/p1/p2/k3 are not zero but ignored: planeloc treats the images as "
        "rectified (no distortion)");
  }
  if (!b) {
    if (!reader.Has("Stereo.b")) {
      reader.AddProblem(camera.line, "Stereo.b (baseline, metres) is missing for the stereo pair");
    }
    return std::nullopt;
  }
  if (*b <= 0) return std::nullopt;
  camera.baseline = *b;
  camera.baseline_key = "Stereo.b";
  return camera;
}

}  // namespace

std::optional<SettingsCamera> ReadSettingsCamera(SettingsReader& reader,
                                                 std::vector<std::string>* warnings) {
  RefuseFisheye(reader);
  const bool orb_slam3 = reader.Has("File.version") || reader.HasPrefix("Camera1.") ||
                         reader.HasPrefix("Camera2.") || reader.Has("Stereo.T_c1_c2");
  if (orb_slam3 && reader.Has("Camera.fx")) {
    reader.AddProblem(reader.LineOf("Camera.fx"),
                      "Camera.fx (ORB-SLAM2 layout) and Camera1.*/File.version (ORB-SLAM3 v1.0 "
                      "layout) in one file: keep one layout");
    return std::nullopt;
  }
  return orb_slam3 ? ReadOrbSlam3(reader, warnings) : ReadOrbSlam2(reader, warnings);
}

StereoCamera ChooseCamera(const StereoCamera& sequence, const std::optional<SettingsCamera>& file,
                          bool from_settings, const std::filesystem::path& settings_path,
                          std::vector<std::string>* warnings) {
  if (file && file->rectifier) {
    const cv::Size size = file->rectifier->size();
    CheckInput(size.width == sequence.width && size.height == sequence.height,
               settings_path.string(), file->line,
               fmt::format("the raw stereo rig of the settings is for {}x{} images, the sequence's "
                           "images are {}x{}",
                           size.width, size.height, sequence.width, sequence.height),
               "give the calibration of these images (LEFT/RIGHT.width/height or "
               "Camera.width/height)");
    return file->rectifier->camera();
  }
  if (!file) {
    CheckInput(!from_settings, settings_path.string(), 0,
               "the calibration of the settings file was asked for, but the file has none",
               "add Camera.fx/fy/cx/cy/bf (ORB-SLAM2) or Camera1.* and Stereo.b (ORB-SLAM3), or "
               "drop --calib-from-settings / System.calibrationFromSettings");
    return sequence;
  }
  const std::string used = from_settings ? "the settings' value is used (calibration from settings)"
                                         : "the sequence's value is used (--calib-from-settings "
                                           "or System.calibrationFromSettings: 1 chooses the "
                                           "settings')";
  auto compare = [&](const std::string& key, const std::string& what, double value, double expected,
                     bool differs) {
    if (!differs) return;
    warnings->push_back(fmt::format("{}: {} = {} (settings) but {} (sequence calibration); {}", key,
                                    what, value, expected, used));
  };
  compare(file->fx_key, "fx", file->fx, sequence.fx, std::abs(file->fx - sequence.fx) > 0.5);
  compare(file->fy_key, "fy", file->fy, sequence.fy, std::abs(file->fy - sequence.fy) > 0.5);
  compare(file->cx_key, "cx", file->cx, sequence.cx, std::abs(file->cx - sequence.cx) > 0.5);
  compare(file->cy_key, "cy", file->cy, sequence.cy, std::abs(file->cy - sequence.cy) > 0.5);
  compare(file->baseline_key, "baseline (m)", file->baseline, sequence.baseline,
          std::abs(file->baseline - sequence.baseline) > 0.005 * sequence.baseline);
  if (!from_settings) return sequence;
  if ((file->width > 0 && file->width != sequence.width) ||
      (file->height > 0 && file->height != sequence.height)) {
    warnings->push_back(fmt::format(
        "Camera.width/height = {}x{} (settings) but the images are {}x{}; the intrinsics of the "
        "settings are used with the images as they are",
        file->width, file->height, sequence.width, sequence.height));
  }
  StereoCamera camera = sequence;
  camera.fx = file->fx;
  camera.fy = file->fy;
  camera.cx = file->cx;
  camera.cy = file->cy;
  camera.baseline = file->baseline;
  try {
    camera.Check();
  } catch (const std::invalid_argument& e) {
    throw InputError(settings_path.string(), file->line,
                     std::string("the settings' calibration is not usable: ") + e.what(),
                     "fix the camera keys, or use the sequence's calibration");
  }
  return camera;
}

}  // namespace planeloc
