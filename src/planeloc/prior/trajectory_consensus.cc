#include "planeloc/prior/trajectory_consensus.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace planeloc {

RobustLocation RobustMedian(std::vector<double>& values) {
  if (values.empty()) throw std::invalid_argument("RobustMedian: no values");
  const std::size_t n = values.size();
  auto mid = values.begin() + static_cast<std::ptrdiff_t>(n / 2);
  std::nth_element(values.begin(), mid, values.end());
  const double median = *mid;
  for (double& value : values) value = std::abs(value - median);
  std::nth_element(values.begin(), mid, values.end());
  const double sigma = std::max(1.4826 * *mid, 0.005);
  return {median, 1.2533 * sigma / std::sqrt(static_cast<double>(n))};
}

TrajectoryConsensus FindTrajectoryConsensus(std::vector<ConsensusWitness> witnesses,
                                            const ConsensusRule& rule) {
  struct Vote {
    std::size_t plane_index;
    Eigen::Vector3d normal;
    RobustLocation location;
    double tolerance;
  };
  std::vector<Vote> votes;
  for (ConsensusWitness& w : witnesses) {
    if (static_cast<int>(w.distances.size()) < rule.min_points) continue;
    const RobustLocation location = RobustMedian(w.distances);
    votes.push_back({w.plane_index, w.normal, location,
                     std::max(rule.tolerance, 3.0 * location.standard_error)});
  }
  const double cos_peer = std::cos(rule.peer_angle_deg * std::numbers::pi / 180.0);
  TrajectoryConsensus best;
  for (const Vote& hypothesis : votes) {
    const double offset = hypothesis.location.median;
    if (std::abs(offset) < rule.min_offset) continue;
    const Eigen::Vector3d direction = hypothesis.normal * (offset > 0 ? 1.0 : -1.0);
    std::vector<double> along;  // supporters' offsets along `direction`
    std::vector<std::size_t> supporters;
    int opposed = 0;
    for (const Vote& v : votes) {
      const double alignment = v.normal.dot(direction);
      if (std::abs(alignment) < cos_peer) continue;
      if (std::abs(v.location.median - alignment * std::abs(offset)) <= v.tolerance) {
        along.push_back(v.location.median / alignment);
        supporters.push_back(v.plane_index);
      } else if (std::abs(v.location.median) <= v.tolerance) {
        ++opposed;  // agrees with the trajectory as it is
      }
    }
    const int support = static_cast<int>(along.size());
    if (support < rule.min_planes || support <= opposed) continue;
    const int best_support = static_cast<int>(best.supporters.size());
    if (support < best_support) continue;
    const RobustLocation location = RobustMedian(along);
    if (support == best_support && std::abs(location.median) >= best.offset.norm()) continue;
    if (std::abs(location.median) < rule.min_offset) continue;
    best.offset = direction * location.median;
    best.supporters = std::move(supporters);
  }
  return best;
}

}  // namespace planeloc
