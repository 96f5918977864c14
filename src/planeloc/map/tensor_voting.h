// Sparse tensor voting on a point cloud (Medioni, Tang & Lee 2000; Liu et al. ROBIO 2012): every
// point gets a surface normal, three saliencies and a class, from votes cast by its neighbours.
//
// Tensor encoding. We use Medioni's NORMAL-space encoding: a point on a surface with normal n is
// the stick tensor n n^T, so a surface point accumulates sticks along its normal and its normal is
// the eigenvector e1 of the LARGEST eigenvalue of the accumulated tensor. (In the tangent /
// covariance encoding used by PCA, a surface is a plate and its normal is the SMALLEST eigenvector;
// the paper's text mixes both readings — it calls walls "plates" with orientation e3 — see
// docs/map.md.) With T = l1 e1e1^T + l2 e2e2^T + l3 e3e3^T, l1 >= l2 >= l3 >= 0:
//   stick saliency l1 - l2  -> surface point, normal e1
//   plate saliency l2 - l3  -> curve point (edge / crease of two surfaces), tangent e3
//   ball  saliency l3       -> junction or clutter (foliage), no orientation
// and the paper's class rule: stick if (l1-l2) >= (l2-l3) and (l1-l2) >= l3; plate if (l2-l3) is
// the largest; ball otherwise.
//
// Passes (both gather votes at the votee from its radius neighbours, found once; neighborhoods.h):
//  1. Ball pass: an unoriented voter at distance vector v from the votee (|v| = l) casts
//     w(l) * (l^2 I - v v^T) / sigma^2, i.e. a ball vote (I - v^ v^T) — the normal plane of the
//     connecting line — scaled by (l/sigma)^2 so that the nearest neighbours, whose direction is
//     dominated by range noise, do not dominate.
//  2. Stick pass: each voter i casts its pass-1 normal n_i along the osculating arc to the votee
//     (Medioni's stick field): with theta = angle between v and the voter's tangent plane, the vote
//     is the normal rotated by 2*theta, weighted by the voter's normalized stick saliency and
//     w(l) * exp(-c * (sigma * kappa)^2), kappa = 2 sin(theta) / l the arc curvature; no vote
//     when |theta| > max_stick_angle. The voter's ball saliency is cast as a ball vote
//     decay * (I - v^ v^T), as in Medioni's framework. Votes across a crease therefore carry the
//     other surface's normal un-blended (the sum of two orthogonal sticks has one of them as e1,
//     whereas PCA averages them), which is why tensor voting beats PCA near plane intersections.
// Decay: the paper writes Decay(d, sigma) = exp(-d / sigma^2) with d = (x_i - x)^2 + (y_i - y)^2,
// i.e. d is the SQUARED distance; so w(l) = exp(-l^2 / sigma^2), a Gaussian in the distance.
//
// Cost O(N k) for k neighbours within `radius_factor * sigma`, found once by a uniform-grid radius
// search (neighborhoods.h). The votes are computed on a copy of the points sorted along a Morton
// curve, so that a votee's neighbours are close in memory whatever the input order (a voxel-
// downsampled map comes in hash order); results are returned in the input order. TBB-parallel
// over votees, each votee's sum in a fixed neighbour order, so results are bit-identical for any
// thread count.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "planeloc/map/neighborhoods.h"

namespace planeloc {

struct TensorVotingOptions {
  double sigma = 0.5;                 // metres: decay scale, w(l) = exp(-l^2 / sigma^2)
  double radius_factor = 1.5;         // neighbour radius = radius_factor * sigma (w(1.5σ) ≈ 0.1)
  double curvature_weight = 10.0;     // c in exp(-c (sigma kappa)^2), dimensionless; large
                                      // because we look for planes, not curved surfaces
  double max_stick_angle_deg = 45.0;  // voters see the votee at most this far off their plane
  int stick_passes = 2;               // refinement passes after the ball pass (0 = ball only)
  // Neighbours kept a point (the nearest; 0 = all). 512 is ~3x a planar neighbourhood of a
  // 0.1 m-voxel map (~180 at 0.75 m) and above a voxelized tree crown, so it only bounds the cost
  // of unfiltered dense clouds (a raw scan near the sensor holds thousands).
  int max_neighbors = 512;

  double radius() const { return radius_factor * sigma; }
  // Throws OptionsError naming the field.
  void Check() const;
};

enum class SaliencyClass : std::uint8_t {
  kSurface = 0,   // stick dominant: on a surface, normal reliable
  kCurve = 1,     // plate dominant: on an edge / crease
  kJunction = 2,  // ball dominant, or no neighbours: clutter, corner, isolated point
};
std::string SaliencyClassName(SaliencyClass saliency_class);

struct TensorVotingResult {
  std::vector<Eigen::Vector3d> normals;  // unit e1 (sign arbitrary); +z for isolated points
  // Saliencies divided by l1 (so stick + plate + ball = 1; all zero for an isolated point).
  std::vector<float> stick;
  std::vector<float> plate;
  std::vector<float> ball;
  std::vector<SaliencyClass> classes;
  Neighborhoods neighborhoods;  // for reuse (plane extraction)

  std::size_t size() const { return normals.size(); }
};

// The paper's class rule on the eigenvalues l1 >= l2 >= l3 >= 0 (see the header comment).
SaliencyClass ClassifySaliency(double l1, double l2, double l3);

// Runs the ball pass and `stick_passes` stick passes on `points` (any frame, metres).
TensorVotingResult RunTensorVoting(const std::vector<Eigen::Vector3d>& points,
                                   const TensorVotingOptions& options);
// Same, with neighbourhoods already found (radius must equal options.radius(), capped at
// options.max_neighbors for the same result).
TensorVotingResult RunTensorVoting(const std::vector<Eigen::Vector3d>& points,
                                   const TensorVotingOptions& options, Neighborhoods neighborhoods);

}  // namespace planeloc
