#include "planeloc/prior/depth_prior_options.h"

#include <string>

#include "planeloc/util/error.h"

namespace planeloc {

void DepthPriorOptions::Check() const {
  stereo.Check();
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
  if (!(zbuffer_relative >= 0))
    throw OptionsError("DepthPriorOptions.zbuffer_relative must be >= 0");
  if (min_points < 6) throw OptionsError("DepthPriorOptions.min_points must be >= 6");
  if (!(min_depth < max_range)) {
    throw OptionsError("DepthPriorOptions.min_depth must be below max_range");
  }
}

}  // namespace planeloc
