#include "planeloc/eval/report.h"

#include <fmt/format.h>

#include <sstream>

#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"

namespace planeloc {
namespace {

nlohmann::json StatsToJson(const ErrorStatistics& stats) {
  return {{"rmse", stats.rmse}, {"mean", stats.mean}, {"median", stats.median}, {"std", stats.std},
          {"min", stats.min},   {"max", stats.max},   {"sse", stats.sse},       {"n", stats.n}};
}

nlohmann::json AlignmentToJson(const Sim3Alignment& alignment) {
  nlohmann::json rotation = nlohmann::json::array();
  for (int r = 0; r < 3; ++r) {
    rotation.push_back(
        {alignment.rotation(r, 0), alignment.rotation(r, 1), alignment.rotation(r, 2)});
  }
  return {{"type", ToString(alignment.type)},
          {"scale", alignment.scale},
          {"rotation", rotation},
          {"translation",
           {alignment.translation.x(), alignment.translation.y(), alignment.translation.z()}}};
}

std::string StatsRow(const std::string& name, const ErrorStatistics& s) {
  return fmt::format("{:<16}{:>7}{:>12.6f}{:>12.6f}{:>12.6f}{:>12.6f}{:>12.6f}{:>12.6f}\n", name,
                     s.n, s.rmse, s.mean, s.median, s.std, s.min, s.max);
}

}  // namespace

nlohmann::json ReportToJson(const EvalInputs& inputs, const EvalOptions& options,
                            const EvalReport& report) {
  nlohmann::json json;
  json["ape"] = StatsToJson(report.ape.stats);
  if (report.rpe) {
    nlohmann::json rpe = StatsToJson(report.rpe->translation);
    rpe["rot_deg"] = StatsToJson(report.rpe->rotation_deg);
    rpe["delta"] = options.rpe->delta;
    rpe["delta_unit"] = ToString(options.rpe->delta_unit);
    json["rpe"] = rpe;
  }
  if (report.kitti_drift) {
    json["kitti_drift"] = {{"t_rel_percent", report.kitti_drift->translation_percent},
                           {"r_rel_deg_per_100m", report.kitti_drift->rotation_deg_per_100m},
                           {"segments", report.kitti_drift->segments.size()}};
  }
  json["alignment"] = AlignmentToJson(report.ape.alignment);
  json["inputs"] = {{"gt", inputs.gt_path.string()},
                    {"est", inputs.est_path.string()},
                    {"format", options.euroc_reference                      ? "euroc"
                               : options.format == TrajectoryFormat::kKitti ? "kitti"
                                                                            : "tum"},
                    {"gt_poses", inputs.gt_size},
                    {"est_poses", inputs.est_size},
                    {"associated_poses", inputs.reference.size()},
                    {"plane", ToString(options.plane)},
                    {"plane_before_align", options.plane_before_align}};
  return json;
}

std::string FormatReportTable(const EvalInputs& inputs, const EvalOptions& options,
                              const EvalReport& report) {
  std::string text = fmt::format("GT        {} ({} poses)\nestimate  {} ({} poses, {} paired)\n",
                                 inputs.gt_path.string(), inputs.gt_size, inputs.est_path.string(),
                                 inputs.est_size, inputs.reference.size());
  const Sim3Alignment& a = report.ape.alignment;
  text += fmt::format("alignment {}", ToString(a.type));
  if (a.type == AlignmentType::kSim3) text += fmt::format(" (scale {:.6f})", a.scale);
  if (options.plane != ProjectionPlane::kNone) {
    text += fmt::format(", projected to {} {}", ToString(options.plane),
                        options.plane_before_align ? "before alignment" : "after alignment");
  }
  text += "\n\n";
  text += fmt::format("{:<16}{:>7}{:>12}{:>12}{:>12}{:>12}{:>12}{:>12}\n", "metric", "n", "rmse",
                      "mean", "median", "std", "min", "max");
  text += StatsRow("APE trans (m)", report.ape.stats);
  if (report.rpe) {
    text += StatsRow("RPE trans (m)", report.rpe->translation);
    text += StatsRow("RPE rot (deg)", report.rpe->rotation_deg);
    text += fmt::format(
        "(RPE delta {} {}{}{})\n", options.rpe->delta, ToString(options.rpe->delta_unit),
        options.rpe->all_pairs ? ", all pairs" : ", consecutive pairs",
        options.rpe->pairs_from_reference ? ", pairs on GT path" : ", pairs on estimate path");
  }
  if (report.kitti_drift) {
    text +=
        fmt::format("\nKITTI drift  t_rel {:.4f} %   r_rel {:.4f} deg/100m   ({} segments)\n",
                    report.kitti_drift->translation_percent,
                    report.kitti_drift->rotation_deg_per_100m, report.kitti_drift->segments.size());
  }
  return text;
}

void WritePlotCsv(const std::filesystem::path& path, const EvalInputs& inputs,
                  const EvalReport& report) {
  std::ostringstream stream;
  PoseMatrices estimate = inputs.estimate;
  if (!report.ape.estimate.empty()) ApplyAlignment(report.ape.alignment, &estimate);
  stream << (inputs.has_time ? "time" : "frame") << ",gt_x,gt_y,gt_z,est_x,est_y,est_z,ape\n";
  for (std::size_t i = 0; i < inputs.reference.size(); ++i) {
    const Eigen::Vector3d g = inputs.reference[i].block<3, 1>(0, 3);
    const Eigen::Vector3d e = estimate[i].block<3, 1>(0, 3);
    stream << fmt::format("{},{},{},{},{},{},{},{}\n", inputs.times[i], g.x(), g.y(), g.z(), e.x(),
                          e.y(), e.z(), report.ape.errors[i]);
  }
  WriteFileWhole(path, stream.str());
}

}  // namespace planeloc
