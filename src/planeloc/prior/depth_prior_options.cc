#include "planeloc/prior/depth_prior_options.h"

#include <string>

#include "planeloc/util/error.h"

namespace planeloc {

void CloudSurfaceOptions::Check() const {
  if (!(radius > 0)) throw OptionsError("CloudSurfaceOptions.radius must be > 0 (m)");
  if (min_points < 3) throw OptionsError("CloudSurfaceOptions.min_points must be >= 3");
  if (!(max_thickness > 0)) {
    throw OptionsError("CloudSurfaceOptions.max_thickness must be > 0 (m)");
  }
  if (!(min_spread >= 0 && min_spread < 1)) {
    throw OptionsError("CloudSurfaceOptions.min_spread must be in [0, 1)");
  }
}

void DepthPriorOptions::Check() const {
  stereo.Check();
  surfaces.Check();
  const auto positive = [](double value, const char* name) {
    if (!(value > 0)) throw OptionsError(std::string("DepthPriorOptions.") + name + " must be > 0");
  };
  positive(voxel_size, "voxel_size");
  positive(max_range, "max_range");
  positive(min_depth, "min_depth");
  positive(disparity_sigma, "disparity_sigma");
  positive(weight, "weight");
  positive(sample_cell, "sample_cell");
  positive(max_points, "max_points");
  positive(occlusion_margin, "occlusion_margin");
  positive(huber, "huber");
  positive(edge_tolerance, "edge_tolerance");
  positive(max_correction, "max_correction");
  positive(max_correction_deg, "max_correction_deg");
  if (!(zbuffer_relative >= 0))
    throw OptionsError("DepthPriorOptions.zbuffer_relative must be >= 0");
  if (min_points < 6) throw OptionsError("DepthPriorOptions.min_points must be >= 6");
  if (!(min_depth < max_range)) {
    throw OptionsError("DepthPriorOptions.min_depth must be below max_range");
  }
}

}  // namespace planeloc
