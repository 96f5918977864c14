// What one run learned about the planes of its plane map: the file `planeloc run --map-update`
// writes and `planeloc map update` reads (docs/map-update.md):
//   {"format":"planeloc map updates 1",
//    "planes_file":{"path":str,"fnv1a64":"16 hex digits","planes":int,"frame":str},
//    "run":{"sequence":str,"frames":int,"trajectory":str},
//    "planes":[{"id":int,"status":"unseen"|"confirmed"|"corrected"|"contradicted",
//               "points":int,"through":int,"frames":[int,...],"disabled_at_frame":int|null,
//               "offset":m,"offset_sigma":m,"tilt":[rad,rad],"tilt_sigma":[rad,rad],
//               "normal":[nx,ny,nz],"d":m}, ...]}
// One entry per plane of the map, in the map's order. offset is the plane's measured displacement
// along its normal at its centroid (points sit at +offset from the map's plane); tilt its rotation
// about the map's major axis and about n x major axis (as PlaneSigma); normal and d the corrected
// plane. The measurement fields are present for confirmed and corrected planes only.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace planeloc {

enum class PlaneUpdateStatus {
  kUnseen,        // too few points measured it to say anything
  kConfirmed,     // measured where the map has it (within the measurement's uncertainty)
  kCorrected,     // measured, and significantly off the map's plane: offset / tilt given
  kContradicted,  // the run saw through it: points behind the plane, none on it
};
const char* ToString(PlaneUpdateStatus status);

struct PlaneUpdate {
  int id = 0;
  PlaneUpdateStatus status = PlaneUpdateStatus::kUnseen;
  int points = 0;           // map points that measured its offset (latest estimate of each)
  int through = 0;          // map points seen through it (behind it, on a ray crossing its outline)
  std::vector<int> frames;  // keyframes' frame indices whose windows measured it, ascending
  std::optional<int> disabled_at_frame;  // the run stopped using it (the bias test), if it did
  // Confirmed and corrected: the measured correction of the map's plane and its uncertainty
  // (the trajectory's own error included, docs/map-update.md).
  double offset = 0;                               // metres, along the normal, at the centroid
  double offset_sigma = 0;                         // metres
  Eigen::Vector2d tilt = Eigen::Vector2d::Zero();  // radians, about major axis, n x it
  Eigen::Vector2d tilt_sigma = Eigen::Vector2d::Zero();  // radians
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();      // the corrected plane n.x + d = 0
  double d = 0;

  bool measured() const {
    return status == PlaneUpdateStatus::kConfirmed || status == PlaneUpdateStatus::kCorrected;
  }
};

// The normal after the small rotations of `tilt` (radians): tilt[0] about e1 (the major axis, in
// the plane), tilt[1] about e2 = n x e1. A rotation by t about e1 turns n towards -e2, one about
// e2 towards +e1. The convention of the file's "tilt", shared by the run and `map update`.
Eigen::Vector3d TiltedNormal(const Eigen::Vector3d& normal, const Eigen::Vector3d& e1,
                             const Eigen::Vector2d& tilt);

struct MapUpdates {
  std::filesystem::path planes_path;  // planes.json the run used, as given to it
  std::string planes_hash;            // FileHash of that file
  int planes_count = 0;
  std::string frame_name;  // the plane map's frame name ("" when the file has none)
  std::string sequence;    // what the run tracked (a folder or a bag)
  int frames = 0;
  std::string trajectory;
  std::vector<PlaneUpdate> planes;
  std::filesystem::path source;  // the file ReadMapUpdates read (for messages); not written
};

// FNV-1a (64 bit) of the file's bytes as 16 lowercase hex digits: identifies the planes.json a
// run used. Throws InputError naming the file when it cannot be read.
std::string FileHash(const std::filesystem::path& path);

// Written whole (util/safe_file.h). Throws InputError naming the path on failure.
void WriteMapUpdates(const std::filesystem::path& path, const MapUpdates& updates);
// Throws InputError naming the file (and the plane entry) on a malformed document: unknown
// format or status, a sigma that is not positive and finite for a measured plane, a repeated id.
MapUpdates ReadMapUpdates(const std::filesystem::path& path);

}  // namespace planeloc
