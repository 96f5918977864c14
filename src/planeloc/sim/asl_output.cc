#include "planeloc/sim/asl_output.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <string>

#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

namespace planeloc::sim {
namespace {

// Shortest round-trip digits, with ".0" on integral values as EuRoC's files (and Python's repr)
// write them: "1.0", not "1", so the matrix reads as the floats it is.
std::string Number(double value) {
  std::string text = fmt::format("{}", value);
  if (text.find_first_of(".eEn") == std::string::npos) text += ".0";
  return text;
}

std::string List(const double* values, int count) {
  std::string text;
  for (int i = 0; i < count; ++i) text += (i > 0 ? ", " : "") + Number(values[i]);
  return text;
}

// The checks AslSequence and ReadEurocTrajectory apply on reading, made here so that a bad call
// fails before writing a file the reader would reject.
void CheckStamps(const std::filesystem::path& path, const std::vector<std::int64_t>& stamps_ns) {
  CheckInput(!stamps_ns.empty(), path.string(), 0, "no timestamps to write",
             "an ASL sequence has at least one frame");
  for (std::size_t i = 0; i < stamps_ns.size(); ++i) {
    CheckInput(stamps_ns[i] >= 0 && (i == 0 || stamps_ns[i] > stamps_ns[i - 1]), path.string(), 0,
               fmt::format("timestamp {} of frame {} is negative or not after the previous one",
                           stamps_ns[i], i),
               "pass non-negative nanoseconds, strictly increasing");
  }
}

AslCamera EurocCamera(const Eigen::Matrix4d& body_from_sensor, double fu, double fv, double cu,
                      double cv, const Eigen::Vector4d& distortion) {
  AslCamera camera;
  camera.body_from_sensor = Rigid3d::FromMatrix4d(body_from_sensor);
  camera.fu = fu;
  camera.fv = fv;
  camera.cu = cu;
  camera.cv = cv;
  camera.distortion = distortion;
  return camera;
}

}  // namespace

AslCamera EurocCam0() {
  Eigen::Matrix4d t_bs;
  t_bs << 0.0148655429818, -0.999880929698, 0.00414029679422, -0.0216401454975,  //
      0.999557249008, 0.0149672133247, 0.025715529948, -0.064676986768,          //
      -0.0257744366974, 0.00375618835797, 0.999660727178, 0.00981073058949,      //
      0.0, 0.0, 0.0, 1.0;
  return EurocCamera(t_bs, 458.654, 457.296, 367.215, 248.375,
                     Eigen::Vector4d(-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05));
}

AslCamera EurocCam1() {
  Eigen::Matrix4d t_bs;
  t_bs << 0.0125552670891, -0.999755099723, 0.0182237714554, -0.0198435579556,  //
      0.999598781151, 0.0130119051815, 0.0251588363115, 0.0453689425024,        //
      -0.0253898008918, 0.0179005838253, 0.999517347078, 0.00786212447038,      //
      0.0, 0.0, 0.0, 1.0;
  return EurocCamera(t_bs, 457.587, 456.134, 379.999, 255.238,
                     Eigen::Vector4d(-0.28368365, 0.07451284, -0.00010473, -3.55590700e-05));
}

void WriteAslCameraYaml(const std::filesystem::path& path, const AslCamera& camera,
                        const std::string& comment) {
  CheckInput(camera.width >= 1 && camera.height >= 1 && camera.fu > 0 && camera.fv > 0 &&
                 camera.rate_hz > 0,
             path.string(), 0,
             fmt::format("camera {}x{}, fu {}, fv {}, rate {} Hz: size, focal lengths and rate "
                         "must be positive",
                         camera.width, camera.height, camera.fu, camera.fv, camera.rate_hz),
             "fill AslCamera (EurocCam0() is EuRoC's cam0)");
  // A newline in the comment would end the YAML scalar and corrupt the file.
  CheckInput(comment.find_first_of("\r\n") == std::string::npos, path.string(), 0,
             "the sensor comment holds a line break", "pass a one-line comment");
  const Eigen::Matrix4d t_bs = camera.body_from_sensor.Matrix4d();
  std::string rows;
  for (int r = 0; r < 4; ++r) {
    const double row[4] = {t_bs(r, 0), t_bs(r, 1), t_bs(r, 2), t_bs(r, 3)};
    rows += (r > 0 ? ",\n         " : "") + List(row, 4);
  }
  const double intrinsics[4] = {camera.fu, camera.fv, camera.cu, camera.cv};
  WriteFileWhole(path, fmt::format("# General sensor definitions.\n"
                                   "sensor_type: camera\n"
                                   "comment: {}\n"
                                   "\n"
                                   "# Sensor extrinsics wrt. the body-frame.\n"
                                   "T_BS:\n"
                                   "  cols: 4\n"
                                   "  rows: 4\n"
                                   "  data: [{}]\n"
                                   "\n"
                                   "# Camera specific definitions.\n"
                                   "rate_hz: {}\n"
                                   "resolution: [{}, {}]\n"
                                   "camera_model: pinhole\n"
                                   "intrinsics: [{}] #fu, fv, cu, cv\n"
                                   "distortion_model: radial-tangential\n"
                                   "distortion_coefficients: [{}]\n",
                                   comment, rows, camera.rate_hz, camera.width, camera.height,
                                   List(intrinsics, 4), List(camera.distortion.data(), 4)));
}

std::string AslImageName(std::int64_t stamp_ns) { return fmt::format("{}.png", stamp_ns); }

void WriteAslImageList(const std::filesystem::path& path,
                       const std::vector<std::int64_t>& stamps_ns) {
  CheckStamps(path, stamps_ns);
  std::string text = "#timestamp [ns],filename\n";
  for (const std::int64_t stamp : stamps_ns) {
    text += fmt::format("{},{}\n", stamp, AslImageName(stamp));
  }
  WriteFileWhole(path, text);
}

void WriteAslGroundTruth(const std::filesystem::path& path,
                         const std::vector<std::int64_t>& stamps_ns,
                         const std::vector<Rigid3d>& world_from_body) {
  CheckInput(stamps_ns.size() == world_from_body.size(), path.string(), 0,
             fmt::format("{} timestamps for {} poses", stamps_ns.size(), world_from_body.size()),
             "pass one timestamp per body pose");
  CheckStamps(path, stamps_ns);
  std::string text =
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
      "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], "
      "b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], "
      "b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
  const std::size_t n = world_from_body.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Rigid3d& pose = world_from_body[i];
    Eigen::Vector3d velocity = Eigen::Vector3d::Zero();
    if (n > 1) {
      const std::size_t before = i == 0 ? 0 : i - 1, after = i + 1 == n ? i : i + 1;
      // The difference of the integer stamps first: as doubles, 1.4e18 ns are 256 ns apart.
      const double seconds = static_cast<double>(stamps_ns[after] - stamps_ns[before]) * 1e-9;
      velocity =
          (world_from_body[after].translation - world_from_body[before].translation) / seconds;
    }
    // q and -q are the same rotation; EuRoC's files keep w >= 0.
    Eigen::Quaterniond q = pose.rotation.normalized();
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    const Eigen::Vector3d& p = pose.translation;
    text +=
        fmt::format("{},{},{},{},{},{},{},{},{},{},{},0,0,0,0,0,0\n", stamps_ns[i], p.x(), p.y(),
                    p.z(), q.w(), q.x(), q.y(), q.z(), velocity.x(), velocity.y(), velocity.z());
  }
  WriteFileWhole(path, text);
}

}  // namespace planeloc::sim
