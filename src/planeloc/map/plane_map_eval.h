// Accuracy of an extracted plane map against ground-truth planes (the simulator's
// world/planes_gt.json): issue 4's acceptance measures, shared by the tests and by
// `planeloc map planes --gt`.
//
// A GT plane is checked if its kind is one of `kinds` and its visible area — the map points within
// `on_plane_distance` of it and inside its polygon, each standing for one voxel face
// (`point_area`) — is at least `min_visible_area`. It is matched by the extracted plane that
// labels most of those visible points (an association by support, not by proximity, so a
// coplanar facade elsewhere on the street cannot stand in for it); the match is good if the
// normals differ by less than `max_angle_deg` and the extracted plane's centroid lies within
// `max_offset` of the GT plane.
#pragma once

#include <Eigen/Core>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "planeloc/io/plane_map.h"

namespace planeloc {

struct PlaneMapEvalOptions {
  std::vector<std::string> kinds = {"ground", "facade"};
  double point_area = 0.01;         // m^2 a map point stands for (voxel size 0.10 m squared)
  double min_visible_area = 20.0;   // m^2
  double on_plane_distance = 0.05;  // m: a map point within this of a GT plane sees it
  double max_angle_deg = 1.0;
  double max_offset = 0.05;         // m
  double labelled_distance = 0.10;  // m: a labelled point this close to any GT plane is right

  void Check() const;  // throws OptionsError naming the field
};

struct GtPlaneMatch {
  int gt_id = -1;
  std::string kind;
  double visible_area = 0.0;  // m^2
  int extracted_id = -1;      // -1: no extracted plane labels any of its visible points
  double support = 0.0;       // fraction of its visible points labelled with extracted_id
  double angle_deg = 180.0;
  double offset = 1e9;  // m, |GT distance of the extracted centroid|
  bool good = false;
};

struct PlaneMapEvaluation {
  std::vector<GtPlaneMatch> checked;  // GT planes of the given kinds with enough visible area
  int good = 0;                       // how many of them are matched within the tolerances
  std::size_t labelled_points = 0;
  double labelled_on_gt = 0.0;  // fraction of labelled points within labelled_distance

  bool AllGood() const { return good == static_cast<int>(checked.size()); }
  nlohmann::json ToJson() const;
};

// The per-point part of EvaluatePlaneMap, which can be summed over pieces of the map (tiles,
// issue 15): per checked GT plane (the GT planes of options.kinds, in file order) the visible point
// count and the votes per extracted id, and the labelled point counts.
struct PlaneMapTally {
  std::vector<std::size_t> visible;
  std::vector<std::map<int, std::size_t>> labels;
  std::size_t labelled = 0, labelled_near = 0;

  void Merge(const PlaneMapTally& other);  // same GT, same options, same extracted ids
  nlohmann::json ToJson() const;
  static PlaneMapTally FromJson(const nlohmann::json& json);
};

PlaneMapTally TallyPlaneMap(const std::vector<Eigen::Vector3d>& map_points,
                            const std::vector<int>& point_plane, const PlaneMap& gt,
                            const PlaneMapEvalOptions& options);
PlaneMapEvaluation FinishPlaneMapEvaluation(const PlaneMapTally& tally, const PlaneMap& extracted,
                                            const PlaneMap& gt, const PlaneMapEvalOptions& options);

// `point_plane[i]` = id of the extracted plane that point i belongs to, or -1.
PlaneMapEvaluation EvaluatePlaneMap(const std::vector<Eigen::Vector3d>& map_points,
                                    const std::vector<int>& point_plane, const PlaneMap& extracted,
                                    const PlaneMap& gt, const PlaneMapEvalOptions& options);

}  // namespace planeloc
