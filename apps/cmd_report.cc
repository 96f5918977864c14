// `planeloc report`: one self-contained HTML page of one or two runs (see eval/html_report.h).
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <memory>
#include <string>

#include "command_registry.h"
#include "planeloc/eval/html_report.h"
#include "planeloc/util/safe_file.h"

namespace planeloc::cli {
namespace {

struct ReportArgs {
  std::string run;
  std::string compare;
  std::string gt;
  std::string out;
  std::string title = "planeloc report";
};

int Run(const ReportArgs& args) {
  CheckOutputPaths({{"--out", args.out}}, {{"--gt", args.gt}});
  HtmlReportOptions options;
  options.run_dir = args.run;
  if (!args.compare.empty()) options.compare_dir = args.compare;
  if (!args.gt.empty()) options.gt_path = args.gt;
  if (const char* dir = std::getenv("PLANELOC_THREE_JS_DIR")) options.three_js_dir = dir;
  options.title = args.title;
  WriteFileWhole(args.out, RenderHtmlReport(options));
  spdlog::info("report: {}", args.out);
  return 0;
}

const CommandRegistrar kRegistrar("report", [](CLI::App& app) -> CommandRunner {
  auto args = std::make_shared<ReportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "One self-contained HTML page of a run (and a second one to compare): 3-D view, "
      "error and tracking plots, keyframe images");
  cmd->add_option("--run", args->run, "Folder written by `planeloc run --report-dir`")->required();
  cmd->add_option("--compare", args->compare, "A second run folder, shown beside the first");
  cmd->add_option("--gt", args->gt, "Ground-truth poses (KITTI or TUM) for the error statistics");
  cmd->add_option("--out", args->out, "Output HTML file")->required();
  cmd->add_option("--title", args->title, "Page title")->capture_default_str();
  return [args] { return Run(*args); };
});

}  // namespace
}  // namespace planeloc::cli
