#include "planeloc/sim/survey_scan.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <string>
#include <unordered_set>

#include "planeloc/sim/shading.h"
#include "planeloc/util/error.h"

namespace planeloc::sim {
namespace {

// Keeps the survey's noise streams apart from ScanLidar's when a caller reuses one seed for both.
constexpr std::uint32_t kSurveyStream = 0x5c4a7u;

// A step that divides the range must give both ends despite 0.1-like steps not being exact
// binary fractions; a millionth of a step is far below anything a step could mean.
constexpr double kGridSlack = 1e-6;

int ElevationRows(const SurveyScanOptions& o) {
  return static_cast<int>(std::floor(
             (o.max_elevation_deg - o.min_elevation_deg) / o.angular_step_deg + kGridSlack)) +
         1;
}

int AzimuthSteps(const SurveyScanOptions& o) {
  return std::max(1, static_cast<int>(std::ceil(360.0 / o.angular_step_deg - kGridSlack)));
}

struct VoxelKey {
  std::int64_t x, y, z;
  bool operator==(const VoxelKey&) const = default;
};

struct VoxelKeyHash {
  std::size_t operator()(const VoxelKey& k) const {
    const auto h = [](std::int64_t v) { return static_cast<std::uint64_t>(v); };
    // Large odd multipliers spread neighbouring cells over the whole table.
    return static_cast<std::size_t>(h(k.x) * 0x9e3779b97f4a7c15ull ^
                                    h(k.y) * 0xc2b2ae3d27d4eb4full ^
                                    h(k.z) * 0x165667b19e3779f9ull);
  }
};

std::int64_t Cell(double coordinate, double voxel) {
  const double cell = std::floor(coordinate / voxel);
  // Beyond 2^62 the cast would be undefined; no scanned scene comes near, a tiny voxel might.
  if (!(std::abs(cell) < 4.6e18)) {
    throw OptionsError("ScanSurveyStations: voxel " + std::to_string(voxel) +
                       " m is too small for coordinates like " + std::to_string(coordinate));
  }
  return static_cast<std::int64_t>(cell);
}

}  // namespace

void SurveyScanOptions::Check() const {
  if (!(angular_step_deg > 0.0 && std::isfinite(angular_step_deg))) {
    throw OptionsError("SurveyScanOptions.angular_step_deg must be > 0 and finite");
  }
  if (!(min_elevation_deg >= -90.0 && max_elevation_deg <= 90.0)) {
    throw OptionsError("SurveyScanOptions: elevations must lie in [-90, 90] degrees");
  }
  if (!(min_elevation_deg <= max_elevation_deg)) {
    throw OptionsError("SurveyScanOptions: min_elevation_deg must be <= max_elevation_deg");
  }
  if (!(min_range >= 0.0 && max_range > min_range && std::isfinite(max_range))) {
    throw OptionsError("SurveyScanOptions: need 0 <= min_range < max_range (finite)");
  }
  if (!(range_noise >= 0.0 && std::isfinite(range_noise))) {
    throw OptionsError("SurveyScanOptions.range_noise must be >= 0 and finite");
  }
}

std::vector<Eigen::Vector3d> ScanSurvey(const Scene& scene, const Eigen::Vector3d& station,
                                        std::uint32_t noise_seed,
                                        const SurveyScanOptions& options) {
  options.Check();
  const int rows = ElevationRows(options);
  const int azimuths = AzimuthSteps(options);
  const Eigen::Vector3f origin = station.cast<float>();
  const double deg = M_PI / 180.0;
  std::vector<std::vector<Eigen::Vector3d>> per_row(static_cast<std::size_t>(rows));
  tbb::parallel_for(0, rows, [&](int row) {
    std::mt19937 rng(HashCombine(noise_seed, kSurveyStream, static_cast<std::uint32_t>(row)));
    // A unit normal scaled by the sigma: std::normal_distribution requires a sigma > 0, and a
    // noise-free scan must still consume the same draws.
    std::normal_distribution<double> unit_noise(0.0, 1.0);
    const double elevation = std::min(options.max_elevation_deg,
                                      options.min_elevation_deg + row * options.angular_step_deg);
    const double cos_el = std::cos(elevation * deg), sin_el = std::sin(elevation * deg);
    std::vector<Eigen::Vector3d>& out = per_row[static_cast<std::size_t>(row)];
    out.reserve(static_cast<std::size_t>(azimuths));
    Hit previous;
    bool hinted = false;
    for (int step = 0; step < azimuths; ++step) {
      const double az = step * options.angular_step_deg * deg;
      const Eigen::Vector3d dir(cos_el * std::cos(az), cos_el * std::sin(az), sin_el);
      const double range_noise = options.range_noise * unit_noise(rng);
      Hit hit;
      const bool found =
          scene.Intersect(origin, dir.cast<float>(), static_cast<float>(options.max_range), &hit,
                          hinted ? &previous : nullptr);
      hinted = found;  // the next azimuth step usually hits the same surface
      if (!found) continue;
      previous = hit;
      if (hit.t < options.min_range) continue;
      out.push_back(station + dir * (static_cast<double>(hit.t) + range_noise));
    }
  });
  std::size_t total = 0;
  for (const auto& row : per_row) total += row.size();
  std::vector<Eigen::Vector3d> points;
  points.reserve(total);
  for (const auto& row : per_row) points.insert(points.end(), row.begin(), row.end());
  return points;
}

std::vector<Eigen::Vector3d> ScanSurveyStations(const Scene& scene,
                                                const std::vector<Eigen::Vector3d>& stations,
                                                std::uint32_t noise_seed, double voxel,
                                                const SurveyScanOptions& options) {
  options.Check();
  if (std::isnan(voxel)) throw OptionsError("ScanSurveyStations: voxel must not be NaN");
  std::vector<Eigen::Vector3d> merged;
  std::unordered_set<VoxelKey, VoxelKeyHash> taken;
  // Thinning each station as it arrives gives the same points as thinning the concatenation
  // (first come, first kept) without holding every station's full sphere at once.
  for (std::size_t i = 0; i < stations.size(); ++i) {
    const std::vector<Eigen::Vector3d> scan = ScanSurvey(
        scene, stations[i], HashCombine(noise_seed, static_cast<std::uint32_t>(i)), options);
    if (!(voxel > 0.0)) {
      merged.insert(merged.end(), scan.begin(), scan.end());
      continue;
    }
    for (const Eigen::Vector3d& p : scan) {
      const VoxelKey key{Cell(p.x(), voxel), Cell(p.y(), voxel), Cell(p.z(), voxel)};
      if (taken.insert(key).second) merged.push_back(p);
    }
  }
  return merged;
}

}  // namespace planeloc::sim
