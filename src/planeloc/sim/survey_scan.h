// A static terrestrial survey scanner (Leica-ScanStation-like) on a tripod: a dense equiangular
// sphere of millimetre-accurate returns from one station, and several stations merged and thinned
// to a voxel grid, as a surveyed room's registered map is delivered. Rows of equal elevation run in
// parallel with TBB and draw their noise from std::mt19937 streams seeded per (seed, row), so the
// output never depends on the thread count.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "planeloc/sim/raycast.h"

namespace planeloc::sim {

struct SurveyScanOptions {
  double angular_step_deg = 0.25;    // azimuth and elevation step
  double min_elevation_deg = -70.0;  // the tripod hides the cone below
  double max_elevation_deg = 90.0;
  double min_range = 0.4;      // metres
  double max_range = 60.0;     // metres
  double range_noise = 0.004;  // metres, Gaussian along the beam (Leica-like mm level)
  void Check() const;          // throws planeloc::OptionsError (util/error.h) on bad values
};

// One full sphere of returns from a scanner standing at `station` (in W, the scene's z-up frame),
// in W. Azimuth over [0, 360) and elevation over [min, max] (both ends included when the step
// divides the range) in steps of angular_step_deg, ordered row by row from the lowest elevation,
// each row by azimuth from +x towards +y. A ray that hits nothing within max_range, or hits closer
// than min_range, gives no point. The noise is drawn for every direction so a lost return never
// shifts the others. As on a real scanner, a row at +90 degrees repeats the zenith once per
// azimuth step.
std::vector<Eigen::Vector3d> ScanSurvey(const Scene& scene, const Eigen::Vector3d& station,
                                        std::uint32_t noise_seed,
                                        const SurveyScanOptions& options = {});

// Several stations merged (in the given order) and thinned to at most one point per `voxel`
// metres cube (keep the first point of each voxel in that order; voxel <= 0 keeps everything):
// a surveyed room's map, as a registered multi-station scan would be delivered. Station i is
// ScanSurvey(scene, stations[i], HashCombine(noise_seed, i), options), so stations never share a
// noise stream. Throws OptionsError for a NaN voxel, or one so small that a cell index would
// overflow 64 bits.
std::vector<Eigen::Vector3d> ScanSurveyStations(const Scene& scene,
                                                const std::vector<Eigen::Vector3d>& stations,
                                                std::uint32_t noise_seed, double voxel,
                                                const SurveyScanOptions& options = {});

}  // namespace planeloc::sim
