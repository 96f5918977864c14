// Plane map from a tensor-voted point cloud (the paper's second step, made robust):
//  1. surface points: class kSurface and normalized stick saliency >= min_stick_saliency;
//  2. axial k-means on their normals (normal_clustering.h), k chosen by merging;
//  3. per orientation cluster, region growing over the tensor-voting neighbourhoods into
//     spatially connected coplanar patches (normal within growth_angle_deg of the patch normal,
//     point within growth_distance of the patch plane, patch plane refitted as it grows);
//  4. robust total-least-squares fit per patch (FitPlaneRobust);
//  5. adjacent patches on the same plane (angle < merge_angle_deg, offsets < merge_distance) are
//     merged when the group's joint plane holds each of them (JointPlaneHoldsAll) — this also
//     joins a plane whose normals straddled two k-means clusters;
//  6. planes with too few inliers, too small an area or extent, or too large an rms are rejected
//     (cars and hedges are small, foliage is rough);
//  7. outline: concave outline of the inliers in plane coordinates (plane_outline.h: occupancy
//     grid, closing, outer boundary of the largest component), area = occupied-cell area.
// Everything is in the cloud's frame (the map frame). Deterministic.
// Up (options.detect_up): after step 5, the largest plane (most inliers, rms <= max_rms) whose
// normal is within 2 kind_angle_deg of a coordinate axis gives the up axis (the normal of the
// largest plane when none is); its sign is the side where most neighbours of the plane's points
// lie more than 3 inlier_distance off it (kerbs, walls, cars and trees stand on the ground;
// nothing lies under it).
#pragma once

#include <Eigen/Core>
#include <vector>

#include "planeloc/io/plane_map.h"
#include "planeloc/map/normal_clustering.h"
#include "planeloc/map/plane_outline.h"
#include "planeloc/map/tensor_voting.h"

namespace planeloc {

struct PlaneExtractionOptions {
  double min_stick_saliency = 0.5;  // (l1 - l2) / l1 a surface point needs, in [0, 1]
  NormalClusteringOptions clustering;
  double growth_angle_deg = 15.0;  // normal vs patch normal during region growing
  double growth_distance = 0.10;   // metres, point to patch plane during region growing
  int min_patch_points = 30;       // smaller grown patches are dropped before fitting
  double inlier_distance = 0.08;   // metres, trimming threshold of the robust fit
  double merge_angle_deg = 3.0;    // adjacent patches closer than this in angle ...
  double merge_distance = 0.10;    // ... and in offset (metres) are one plane
  int min_inliers = 200;           // planes with fewer inliers are rejected
  double min_area = 8.0;           // m^2, smaller planes (cars, signs) are rejected
  double min_extent = 1.8;         // metres, smaller width of the outline's oriented box
  double max_rms = 0.05;           // metres, rougher "planes" (hedges, foliage) are rejected
  // Up direction of the map frame, for the "ground" / "facade" kind and normal orientation.
  // KITTI maps (camera-0 world frame, y down): (0, -1, 0); a raw Velodyne scan: (0, 0, 1).
  Eigen::Vector3d up = Eigen::Vector3d(0.0, -1.0, 0.0);
  // true: `up` is ignored and detected from the dominant horizontal plane (DetectUp below).
  bool detect_up = false;
  double kind_angle_deg = 10.0;  // normal within this of up = ground, of horizontal = facade
  PlaneOutlineOptions outline;   // polygon and area of each plane (min_area applies to this area)

  void Check() const;  // throws OptionsError naming the field
};

struct PlaneExtractionResult {
  PlaneMap plane_map;            // planes sorted by inliers, ids 0..n-1; stats filled
  std::vector<int> point_plane;  // plane id per input point, -1 when not on a plane
  Eigen::Vector3d up = Eigen::Vector3d::Zero();  // unit up used for kinds and orientation
  bool up_detected = false;                      // true when DetectUp chose `up`
};

// "ground" when the unit normal is within kind_angle_deg of `up` (either sign), "facade" when it is
// within kind_angle_deg of horizontal (perpendicular to up), "other" otherwise.
std::string PlaneKind(const Eigen::Vector3d& normal, const Eigen::Vector3d& up,
                      double kind_angle_deg);

// The orientation convention of the extracted planes: ground normals (within kind_angle_deg of
// `up`) point up; other normals have a positive largest component, so the same plane always gets
// the same (n, d).
Plane OrientPlane(const Plane& plane, const Eigen::Vector3d& up, double kind_angle_deg);

// `voting` must come from RunTensorVoting(points, ...). An input without planar structure gives an
// empty plane map (not an error; the caller warns).
PlaneExtractionResult ExtractPlanes(const std::vector<Eigen::Vector3d>& points,
                                    const TensorVotingResult& voting,
                                    const PlaneExtractionOptions& options);

// Robust plane fit used per patch: a deterministic consensus (MSAC: squared distances truncated at
// inlier_distance / 2) plane of up to 2000 of the points, then total least squares refitted on
// the points within inlier_distance / 2 of it; the inliers are the points within
// `inlier_distance`. Unlike trimming from a least-squares start, or a consensus by inlier count,
// it settles on the dominant layer of two parallel surfaces a few centimetres apart (road and
// sidewalk) rather than on a plane tilted across both (docs/map.md, step 4).
// Returns false when fewer than 3 inliers remain. Exposed for tests.
bool FitPlaneRobust(const std::vector<Eigen::Vector3d>& points, const std::vector<int>& indices,
                    double inlier_distance, Plane& plane, std::vector<int>& inliers, double& rms);

// The first and second moments of a set of points on a plane, with the plane's own normal: what
// the joint fit of several such sets needs (the parallel-axis theorem), without the points.
struct PlanarPartMoments {
  double count = 0;                                   // points
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();     // their mean
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();  // sum of (p - mean)(p - mean)^T, m^2
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // the part's own plane
  double own_residual = 0;  // m^2: sum of squared distances to its own best plane (scatter's
                            // smallest eigenvalue); set by Finish()
  // Sets own_residual from the scatter.
  void Finish();
};
// True when the total-least-squares plane of all the parts' points holds each part as well as
// its own plane does: the part's normal within merge_angle_deg of the joint one, and the part's
// root-mean-square distance to the joint plane exceeding the one to its own best plane by at most
// inlier_distance / 4 (sqrt of the difference of the mean squares). Pieces of one plane fit the
// joint plane as well as their own, whatever their noise; parts that are pairwise within
// merge_distance but are layers of a step (a road and a kerb-high sidewalk, 11 cm, which a joint
// plane tilted by 1 deg across a 9 m street holds within inlier_distance) or a chain along a road
// whose height changes do not. Used by the patch merge and by the merge across tile borders.
bool JointPlaneHoldsAll(const std::vector<const PlanarPartMoments*>& parts,
                        const PlaneExtractionOptions& options);

// Convex hull (counter-clockwise) of 2-D points and its area; exposed for tests (and to compare
// the concave outline against).
std::vector<Eigen::Vector2d> ConvexHull2d(std::vector<Eigen::Vector2d> points);
double PolygonArea2d(const std::vector<Eigen::Vector2d>& polygon);

}  // namespace planeloc
