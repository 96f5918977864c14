// The coarse search of map registration (docs/map-registration.md, steps 1 and 2): votes that
// turn structure points into candidate corrections before any refinement.
//  - Height: each point over a ground plane votes for the vertical shift that puts it on it.
//  - Heading x horizontal shift: for each heading of a grid, each point votes, for every facade
//    it could lie on, for the line of horizontal shifts that puts it on that facade (a Hough
//    transform in shift space). The line is clipped to the facade's extent, so a point votes only
//    for shifts that keep it on the wall, not on the wall's infinite extension.
#pragma once

#include <Eigen/Core>
#include <vector>

#include "planeloc/geometry/plane.h"

namespace planeloc {

// 1-D histogram of vertical shifts (metres) in bins of `bin` over [-range, range], smoothed with
// a [0.5 1 0.5] kernel; returns the centre of the fullest bin (0 without votes).
double VoteVerticalShift(const std::vector<double>& shifts, double range, double bin);

// A facade as the Hough transform sees it.
struct HoughFacade {
  Plane plane;
  Eigen::Vector3d normal;  // horizontal part of the plane normal, unit
  double normal_norm = 1;  // length of that horizontal part before normalization
  Eigen::Vector3d along;   // horizontal in-facade direction: up x normal
  // Extent of the outline along `along` and along up; +-inf when the facade has no outline.
  double along_lo, along_hi, height_lo, height_hi;
};

// Builds the Hough description of `plane` (`outline` may be empty) for the given up direction.
HoughFacade MakeHoughFacade(const Plane& plane, const std::vector<Eigen::Vector3d>& outline,
                            const Eigen::Vector3d& up);

// The horizontal shift grid: shift = (ix cell - half_range[0]) axis[0] +
// (iy cell - half_range[1]) axis[1].
struct ShiftGrid {
  Eigen::Vector3d axis[2];
  double half_range[2] = {0, 0};
  double cell = 0.25;
  int cells[2] = {1, 1};
};

struct HeadingShiftPeak {
  double votes = 0;
  double heading = 0;        // radians about up, at the pivot
  Eigen::Vector3d shift_xy;  // horizontal shift (no vertical part)
};

struct HoughOptions {
  double outline_margin = 0.5;  // metres the facade extent is grown by
  int peaks_per_heading = 3;
};

// Votes `points` (world frame, already shifted vertically) for each heading in `headings`
// (rotation about `up` through `pivot`) and returns the local maxima of the box-filtered
// accumulator, the `peaks_per_heading` best of each heading, best first overall.
std::vector<HeadingShiftPeak> VoteHeadingAndShift(
    const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& pivot,
    const Eigen::Vector3d& up, const std::vector<HoughFacade>& facades,
    const std::vector<double>& headings, const ShiftGrid& grid, const HoughOptions& options);

}  // namespace planeloc
