// The plane map: planes extracted from a LiDAR map, as stored in planes.json:
//   {"planes":[{"id":int,"normal":[nx,ny,nz],"d":float,"centroid":[..],"inliers":int,"rms":float,
//               "area":float,"polygon":[[x,y,z],...],
//               "sigma":{"offset":m,"normal":[rad,rad],"major_axis":[x,y,z]},
//               "provenance":[{...}, ...]}], "stats":{...},
//    "frame":{"name":str,"map":str,"up":[ux,uy,uz],"up_source":"given"|"detected"}}
// with n . x + d = 0, |n| = 1, all in map coordinates: the frame of the point cloud the planes were
// extracted from. "frame" is optional (files written before issue 17 have none). The simulator's
// planes_gt.json uses the same reader ("kind" is optional there, missing fields default to zero).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "planeloc/geometry/plane.h"

namespace planeloc {

// How well the map knows a plane (map planes, docs/map.md "Plane uncertainty"): the standard
// deviation of its offset along the normal at the centroid, and of its normal as small rotations
// about `major_axis` (the inliers' longest in-plane direction) and about n x major_axis.
struct PlaneSigma {
  double offset = 0;                                     // metres
  Eigen::Vector2d normal = Eigen::Vector2d::Zero();      // radians: about major_axis, about n x it
  Eigen::Vector3d major_axis = Eigen::Vector3d::Zero();  // unit, in the plane

  bool known() const { return offset > 0; }
};
// The sigma of a plane in a file written without one (before issue 32): the former global
// Planes.mapSigma for the offset, and 0.2 deg for the normal (a registration's rotation error,
// docs/map.md). major_axis is then any in-plane unit vector.
constexpr double kDefaultPlaneOffsetSigma = 0.05;    // metres
constexpr double kDefaultPlaneNormalSigma = 0.0035;  // radians (0.2 deg)

struct MapPlane {
  int id = 0;
  Plane plane_in_map;
  std::string kind;  // "ground" | "facade" | "other" | "" (unknown)
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  int inliers = 0;
  double rms = 0.0;                      // metres, RMS point-to-plane distance of the inliers
  double area = 0.0;                     // square metres of the polygon
  std::vector<Eigen::Vector3d> polygon;  // outline in map coordinates, on the plane
  PlaneSigma sigma;                      // the map's own uncertainty of the plane
  // What `planeloc map update` did to the plane, one object per run that reported on it
  // (map/map_update.h); empty for a plane as extracted. Written only when non-empty.
  nlohmann::json provenance = nlohmann::json::array();
};

// The frame the planes are expressed in: the frame of the LiDAR map they were extracted from
// (the user's; `planeloc run` needs its initial pose in the same frame).
struct PlaneMapFrame {
  std::string name;      // the user's name for the map frame ("map" by default); "" unknown
  std::string map_file;  // the point cloud the planes were extracted from; "" unknown
  Eigen::Vector3d up = Eigen::Vector3d::Zero();  // unit "up" in the frame; zero when unknown
  std::string up_source;  // "given" (--up / options) or "detected" (dominant horizontal plane)

  bool known() const { return !name.empty(); }
};

struct PlaneMap {
  std::vector<MapPlane> planes;
  nlohmann::json stats = nlohmann::json::object();
  PlaneMapFrame frame;           // not known() for files without "frame"
  std::filesystem::path source;  // the file ReadPlaneMap read it from (for messages); not written
  // True when the file had no per-plane sigma and every plane got the default (kDefault...).
  bool sigma_defaulted = false;
};

// Throws InputError naming the file (and the plane index) on a malformed document. A sigma that
// is not positive and finite, or present on some planes and missing on others, is an error naming
// the plane and its line; a file with no sigma at all gets the defaults (sigma_defaulted).
PlaneMap ReadPlaneMap(const std::filesystem::path& path);
void WritePlaneMap(const std::filesystem::path& path, const PlaneMap& map);

}  // namespace planeloc
