// `planeloc report`: one self-contained HTML file comparing up to two runs against ground truth.
//
// A report folder (written by `planeloc run --report-dir DIR`) holds
//   run.json        {"mode": "planes" | "vo", "sequence": str, "format": "kitti" | "tum"}
//   trajectory.txt  one pose per frame, in run.json's format
//   stats.jsonl     the per-frame stats of `run --stats`
//   summary.json    the end-of-run summary (<stats>.summary.json)
//   settings.yaml   the effective settings (<out>.config.yaml)
//   planes.json     the plane map the run used (plane mode only)
//   map_update.json what the run learned about each plane (`run --map-update`): the 3-D view
//                   colours the planes by it (unseen, confirmed, corrected, contradicted)
//   keyframes/*.jpg a few keyframe overlays (LSD segments, plane outlines, features by plane;
//                   .png is read too)
// Only trajectory.txt is required; a missing optional file leaves its part of the report out.
//
// The HTML inlines everything it shows: the data as JSON, three.js (Debian's libjs-three) for the
// 3-D view, the keyframe images as base64, so it opens offline and fetches nothing.
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace planeloc {

struct HtmlReportOptions {
  std::filesystem::path run_dir;                     // required
  std::optional<std::filesystem::path> compare_dir;  // a second run, shown beside the first
  std::optional<std::filesystem::path> gt_path;      // KITTI or TUM poses (by the first line)
  // three.min.js (and examples/js/controls/OrbitControls.js when there) are read from here.
  std::filesystem::path three_js_dir = "/usr/share/javascript/three";
  std::string title = "planeloc report";
};

// The data the page draws, as embedded in it (see html_report.cc for the keys). Errors are
// position errors in the runs' world frame without any alignment (the plane map fixes the frame),
// paired frame by frame with the GT over the shorter of the two. Throws InputError naming the
// folder or file and the fix when a run folder has no readable trajectory or the GT is unreadable.
nlohmann::json BuildReportData(const HtmlReportOptions& options);

// The whole page. Throws InputError as BuildReportData, and when three.min.js is missing.
std::string RenderHtmlReport(const HtmlReportOptions& options);

// Per-axis decomposition of a position error in a frame with `up`: height along up, along-track
// along the horizontal part of `direction` (the GT's direction of travel), lateral the rest.
struct AxisErrors {
  double lateral = 0, height = 0, along = 0;
};
AxisErrors DecomposeError(const Eigen::Vector3d& error, const Eigen::Vector3d& direction,
                          const Eigen::Vector3d& up);

// RFC 4648 base64 (for the inlined images).
std::string Base64(const std::string& bytes);

}  // namespace planeloc
