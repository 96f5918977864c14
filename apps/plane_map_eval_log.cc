#include "plane_map_eval_log.h"

#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

namespace planeloc::cli {

void LogPlaneMapEvaluation(const std::string& gt, const PlaneMapEvaluation& evaluation,
                           const PlaneMapEvalOptions& options) {
  for (const GtPlaneMatch& m : evaluation.checked) {
    if (!m.good) {
      spdlog::warn(
          "map planes: GT plane {} ({}, {:.0f} m^2 visible) not matched: extracted {} "
          "(support {:.0f} %), angle {:.2f} deg, offset {:.3f} m",
          m.gt_id, m.kind, m.visible_area, m.extracted_id, 100.0 * m.support, m.angle_deg,
          m.offset);
    }
  }
  spdlog::info(
      "map planes vs {}: {}/{} GT {} planes with >= {} m^2 visible matched "
      "(< {} deg, < {} m); {:.2f} % of {} plane points within {} m of a GT plane",
      gt, evaluation.good, evaluation.checked.size(), fmt::join(options.kinds, "/"),
      options.min_visible_area, options.max_angle_deg, options.max_offset,
      100.0 * evaluation.labelled_on_gt, evaluation.labelled_points, options.labelled_distance);
}

}  // namespace planeloc::cli
