// The log of a plane map's evaluation against ground truth (`map planes --gt`), shared by the
// untiled and the tiled `map planes` (cmd_map.cc, map_tiles_cli.cc).
#pragma once

#include <string>

#include "planeloc/map/plane_map_eval.h"

namespace planeloc::cli {

// One warning per checked GT plane not matched, then the summary line (issue 4's acceptance
// numbers). `gt` is the GT file, for the message.
void LogPlaneMapEvaluation(const std::string& gt, const PlaneMapEvaluation& evaluation,
                           const PlaneMapEvalOptions& options);

}  // namespace planeloc::cli
