// The trajectory's offset from a plane map, as the map's facades agree on it in one BA window
// (Planes.trajectoryConsensus; the rule is documented in docs/tracking.md and on
// PlaneAssociationOptions::trajectory_consensus). A point on a correct plane sits n.e off it when
// the trajectory is off by e: facades of about the same normal that show the same offset say
// that the trajectory, not the map, is wrong.
#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace planeloc {

struct RobustLocation {
  double median = 0;
  double standard_error = 0;  // of the median
};

// Median of `values` (reordered; std::invalid_argument when empty) and its standard error from the
// MAD (Gaussian: sigma = 1.4826 MAD, standard error of a median ~1.2533 sigma / sqrt(n)), with a 5
// mm floor on sigma: plane maps and stereo are not better than that.
RobustLocation RobustMedian(std::vector<double>& values);

// One facade's signed distances of the window's points (their visual estimates), metres.
struct ConsensusWitness {
  std::size_t plane_index = 0;  // the caller's index, handed back in the supporters
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  std::vector<double> distances;
};

struct ConsensusRule {
  int min_planes = 3;          // supporters needed (>= 2: one plane could be the wrong one)
  int min_points = 3;          // distances a witness needs to vote
  double min_offset = 0.08;    // metres: smaller offsets are the window BA's
  double tolerance = 0.05;     // metres (or 3 standard errors of the witness's median)
  double peer_angle_deg = 20;  // normals within this angle witness the same direction
};

struct TrajectoryConsensus {
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // e, map frame; zero: none
  std::vector<std::size_t> supporters;               // plane_index of the witnesses that agreed
};

// Each witness's median asks for an offset along its normal. An offset holds when at least
// rule.min_planes witnesses of about that normal explain it within the tolerance and they
// outnumber the witnesses of that normal that agree with the trajectory as it is (one of them
// may be a wrong plane that pulled the trajectory onto itself); witnesses that agree with
// neither do not count. Of the offsets that hold, the one with the most supporters (then the
// smallest) wins.
TrajectoryConsensus FindTrajectoryConsensus(std::vector<ConsensusWitness> witnesses,
                                            const ConsensusRule& rule);

}  // namespace planeloc
