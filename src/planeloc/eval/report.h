// Output of `planeloc eval`: the JSON document, the human table and the plot data file.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "planeloc/eval/evaluation.h"

namespace planeloc {

// {"ape": {rmse, mean, median, std, min, max, sse, n},
//  "rpe": {same keys (translation, m), "rot_deg": {same keys}, "delta", "delta_unit"},
//  "kitti_drift": {"t_rel_percent", "r_rel_deg_per_100m", "segments"},
//  "alignment": {"type", "scale", "rotation" (3 rows), "translation"},
//  "inputs": {...}}; "rpe" / "kitti_drift" only when computed.
nlohmann::json ReportToJson(const EvalInputs& inputs, const EvalOptions& options,
                            const EvalReport& report);

// A fixed-width table for stdout.
std::string FormatReportTable(const EvalInputs& inputs, const EvalOptions& options,
                              const EvalReport& report);

// CSV for tools/plot_trajectory.py: header
// `time,gt_x,gt_y,gt_z,est_x,est_y,est_z,ape` (time = seconds or frame index), one row per
// associated pose; the estimate after alignment, both before any projection (the plot picks its
// own top view). Throws InputError when the file cannot be written.
void WritePlotCsv(const std::filesystem::path& path, const EvalInputs& inputs,
                  const EvalReport& report);

}  // namespace planeloc
