// `planeloc eval`: trajectory error against ground truth, identical to evo (see docs/eval.md).
#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "command_registry.h"
#include "flags.h"
#include "planeloc/eval/report.h"
#include "planeloc/util/error.h"
#include "planeloc/util/safe_file.h"
#include "planeloc/util/temp_dir.h"

extern char** environ;

namespace planeloc::cli {
namespace {

struct EvalArgs {
  std::string gt;
  std::string est;
  std::string format = "kitti";
  std::string gt_times;
  std::string est_times;
  double max_diff = 0.01;
  std::string align = "none";
  std::string plane;
  bool plane_before_align = false;
  double rpe_delta = 0.0;  // 0: no RPE
  std::string rpe_unit = "frames";
  bool rpe_all_pairs = false;
  bool rpe_pairs_from_reference = false;
  bool kitti_drift = false;
  std::string json;
  std::string plot;
  std::vector<std::string> also_est;  // more estimates for --plot
};

// One estimate of the plot: its file, what it was paired with and its errors.
struct PlotEstimate {
  std::string path;
  EvalInputs inputs;
  EvalReport report;
};

// The legend names the alignment only when there was one; `full_path`: the path as given, for
// estimates whose file names are the same (run_planes/trajectory.txt, run_vo/trajectory.txt).
std::string PlotLabel(const PlotEstimate& estimate, bool full_path) {
  const Sim3Alignment& a = estimate.report.ape.alignment;
  std::string label =
      full_path ? estimate.path : std::filesystem::path(estimate.path).filename().string();
  if (a.type == AlignmentType::kSim3) {
    label += fmt::format(" (aligned sim3, scale {:.4f})", a.scale);
  } else if (a.type == AlignmentType::kSe3) {
    label += " (aligned se3)";
  }
  return label + fmt::format(", APE rmse {:.3f} m", estimate.report.ape.stats.rmse);
}

// tools/plot_trajectory.py: $PLANELOC_TOOLS_DIR, then beside the build tree
// (build/bin/../../tools), then the source tree this binary was built from.
std::filesystem::path FindPlotScript() {
  std::vector<std::filesystem::path> candidates;
  if (const char* dir = std::getenv("PLANELOC_TOOLS_DIR")) candidates.emplace_back(dir);
  std::error_code error;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", error);
  if (!error) candidates.push_back(exe.parent_path().parent_path().parent_path() / "tools");
#ifdef PLANELOC_SOURCE_DIR
  candidates.push_back(std::filesystem::path(PLANELOC_SOURCE_DIR) / "tools");
#endif
  for (const auto& dir : candidates) {
    const std::filesystem::path script = dir / "plot_trajectory.py";
    if (std::filesystem::exists(script)) return script;
  }
  throw InputError(
      "", "tools/plot_trajectory.py not found (needed by --plot)",
      "run planeloc from its build tree or set PLANELOC_TOOLS_DIR to the tools folder");
}

// Runs `argv` with MPLBACKEND=Agg (no display needed), output discarded when `quiet`; returns the
// exit code, 127 if the program cannot be started.
int RunWithAggBackend(const std::vector<std::string>& argv, bool quiet) {
  std::vector<std::string> env_strings;
  for (char** e = environ; *e != nullptr; ++e) {
    if (std::strncmp(*e, "MPLBACKEND=", 11) != 0) env_strings.emplace_back(*e);
  }
  env_strings.emplace_back("MPLBACKEND=Agg");
  std::vector<char*> env;
  for (auto& s : env_strings) env.push_back(s.data());
  env.push_back(nullptr);
  std::vector<std::string> args = argv;
  std::vector<char*> c_args;
  for (auto& s : args) c_args.push_back(s.data());
  c_args.push_back(nullptr);
  std::fflush(stdout);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  if (quiet) {
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  }
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, c_args[0], &actions, nullptr, c_args.data(), env.data());
  posix_spawn_file_actions_destroy(&actions);
  if (spawned != 0) return 127;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return 127;
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 1;
}

void WritePlot(const EvalArgs& args, const std::vector<PlotEstimate>& estimates,
               const EvalOptions& options) {
  const std::filesystem::path script = FindPlotScript();
  const TempDir temp("planeloc-eval");
  std::vector<std::string> csv_args;
  std::set<std::string> names;
  for (const PlotEstimate& estimate : estimates) {
    names.insert(std::filesystem::path(estimate.path).filename().string());
  }
  const bool full_paths = names.size() < estimates.size();
  for (std::size_t i = 0; i < estimates.size(); ++i) {
    const std::filesystem::path csv = temp.path() / fmt::format("plot{}.csv", i);
    WritePlotCsv(csv, estimates[i].inputs, estimates[i].report);
    csv_args.insert(csv_args.end(),
                    {"--csv", csv.string(), "--label", PlotLabel(estimates[i], full_paths)});
  }
  std::string plane = ToString(options.plane);
  if (options.plane == ProjectionPlane::kNone) {
    // KITTI camera frames have the ground in x-z; TUM files are usually z-up.
    plane = options.format == TrajectoryFormat::kKitti ? "xz" : "xy";
  }
  const EvalReport& report = estimates.front().report;
  const std::string title =
      estimates.size() == 1
          ? fmt::format("{} vs {} (align {}, APE rmse {:.3f} m)",
                        std::filesystem::path(args.est).filename().string(),
                        std::filesystem::path(args.gt).filename().string(),
                        ToString(report.ape.alignment.type), report.ape.stats.rmse)
          : fmt::format("{} estimates vs {} (align {})", estimates.size(),
                        std::filesystem::path(args.gt).filename().string(),
                        ToString(report.ape.alignment.type));
  // The first python that imports matplotlib wins: a pyenv/venv `python3` on PATH often lacks it
  // while Debian's /usr/bin/python3 has python3-matplotlib. Probes are silent.
  std::vector<std::string> pythons = {"python3", "/usr/bin/python3"};
  if (const char* python = std::getenv("PLANELOC_PYTHON")) pythons.insert(pythons.begin(), python);
  // matplotlib writes a temporary file beside --plot, renamed into place when it succeeded.
  const std::filesystem::path temporary = TemporaryPathFor(args.plot);
  int code = 127;
  std::string chosen;
  for (const std::string& python : pythons) {
    const int probe = RunWithAggBackend({python, "-c", "import matplotlib"}, /*quiet=*/true);
    if (probe == 0) {
      chosen = python;
      break;
    }
    if (probe != 127) code = 3;  // python found, matplotlib missing
  }
  if (!chosen.empty()) {
    std::vector<std::string> command = {chosen, script.string()};
    command.insert(command.end(), csv_args.begin(), csv_args.end());
    command.insert(command.end(),
                   {"--out", temporary.string(), "--plane", plane, "--title", title});
    code = RunWithAggBackend(command, /*quiet=*/false);
  }
  if (code != 0 && temporary != args.plot) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
  }
  if (code == 127) {
    throw InputError(args.plot, "--plot needs python3, which was not found",
                     "install python3 and python3-matplotlib (./scripts/setup.sh) or drop --plot");
  }
  if (code == 3) {
    throw InputError(args.plot, "--plot needs matplotlib, which python3 cannot import",
                     "install python3-matplotlib (./scripts/setup.sh) or drop --plot");
  }
  if (code != 0) {
    throw InputError(
        args.plot,
        fmt::format("{} failed with exit code {} (its message is above)", script.string(), code),
        "check the output folder and the free disk space");
  }
  CommitTemporary(temporary, args.plot);
}

EvalOptions ToOptions(const EvalArgs& args) {
  EvalOptions options;
  options.euroc_reference = args.format == "euroc";
  options.format = ParseTrajectoryFormat(options.euroc_reference ? "tum" : args.format);
  if (!args.gt_times.empty()) options.gt_times = args.gt_times;
  if (!args.est_times.empty()) options.est_times = args.est_times;
  options.max_time_difference_s = args.max_diff;
  options.alignment = ParseAlignmentType(args.align);
  options.plane = ParseProjectionPlane(args.plane);
  options.plane_before_align = args.plane_before_align;
  if (args.rpe_delta > 0.0) {
    RpeOptions rpe;
    rpe.delta = args.rpe_delta;
    rpe.delta_unit = ParseDeltaUnit(args.rpe_unit);
    rpe.all_pairs = args.rpe_all_pairs;
    rpe.pairs_from_reference = args.rpe_pairs_from_reference;
    options.rpe = rpe;
  }
  options.kitti_drift = args.kitti_drift;
  options.Check();
  return options;
}

int Run(const EvalArgs& args) {
  CheckFlag(AtLeast(args.max_diff, 0.0), "--max-diff", args.max_diff,
            "a time difference in seconds, >= 0", "e.g. --max-diff 0.01");
  CheckFlag(AtLeast(args.rpe_delta, 0.0), "--rpe-delta", args.rpe_delta,
            "a number >= 0 of --rpe-unit (frames or metres; 0 = no RPE)", "e.g. --rpe-delta 1");
  CheckInput(args.also_est.empty() || !args.plot.empty(), "", 0,
             "--also-est adds estimates to the plot, and no --plot was given",
             "add --plot FILE.png, or drop --also-est");
  std::vector<FlagPath> input_paths = {{"--gt", args.gt},
                                       {"--est", args.est},
                                       {"--gt-times", args.gt_times},
                                       {"--est-times", args.est_times}};
  for (const std::string& also : args.also_est) input_paths.push_back({"--also-est", also});
  CheckOutputPaths({{"--json", args.json}, {"--plot", args.plot}}, input_paths);
  const EvalOptions options = ToOptions(args);
  const EvalInputs inputs = LoadEvalInputs(args.gt, args.est, options);
  const EvalReport report = Evaluate(inputs, options);
  std::fputs(FormatReportTable(inputs, options, report).c_str(), stdout);
  std::fflush(stdout);  // before --json /dev/stdout, which writes through its own stream
  if (!args.json.empty())
    WriteFileWhole(args.json, ReportToJson(inputs, options, report).dump(2) + '\n');
  if (!args.plot.empty()) {
    std::vector<PlotEstimate> estimates = {{args.est, inputs, report}};
    for (const std::string& also : args.also_est) {
      // Same options as --est, except --est-times (those are the times of --est): KITTI files
      // are paired line by line, TUM files by their own stamps.
      EvalOptions also_options = options;
      also_options.est_times.reset();
      EvalInputs also_inputs = LoadEvalInputs(args.gt, also, also_options);
      EvalReport also_report = Evaluate(also_inputs, also_options);
      spdlog::info("--also-est {}: APE rmse {:.6f} m over {} poses (plotted, not in the table)",
                   also, also_report.ape.stats.rmse, also_inputs.reference.size());
      estimates.push_back({also, std::move(also_inputs), std::move(also_report)});
    }
    WritePlot(args, estimates, options);
  }
  return 0;
}

const CommandRegistrar kRegistrar("eval", [](CLI::App& app) -> CommandRunner {
  auto args = std::make_shared<EvalArgs>();
  CLI::App* cmd = app.add_subcommand(
      "eval", "Trajectory error against ground truth: APE, RPE, KITTI drift (identical to evo)");
  cmd->add_option("--gt", args->gt, "Ground-truth trajectory")->required();
  cmd->add_option("--est", args->est, "Estimated trajectory")->required();
  cmd->add_option("--format", args->format,
                  "kitti | tum | euroc (the GT an ASL/EuRoC csv, e.g. "
                  "mav0/state_groundtruth_estimate0/data.csv; the estimate TUM; paired by "
                  "timestamp within --max-diff, as evo_ape euroc)")
      ->check(CLI::IsMember({"kitti", "tum", "euroc"}))
      ->capture_default_str();
  cmd->add_option("--gt-times", args->gt_times, "KITTI: times.txt of the GT (one line per pose)");
  cmd->add_option("--est-times", args->est_times,
                  "KITTI: times of the estimate; with --gt-times, pair poses by timestamp");
  cmd->add_option("--max-diff", args->max_diff, "Timestamp association tolerance, s")
      ->capture_default_str();
  cmd->add_option("--align", args->align, "none | se3 | sim3 (Umeyama on positions)")
      ->check(CLI::IsMember({"none", "se3", "sim3"}))
      ->capture_default_str();
  cmd->add_option("--plane", args->plane,
                  "xz | xy | yz: project after alignment (KITTI ground plane is xz)")
      ->check(CLI::IsMember({"xz", "xy", "yz"}));
  cmd->add_flag("--plane-before-align", args->plane_before_align,
                "APE: project before aligning (evo library order) instead of after");
  cmd->add_option("--rpe-delta", args->rpe_delta, "RPE delta (0 = no RPE)");
  cmd->add_option("--rpe-unit", args->rpe_unit, "frames | m")
      ->check(CLI::IsMember({"frames", "f", "m", "meters", "metres"}))
      ->capture_default_str();
  cmd->add_flag("--rpe-all-pairs", args->rpe_all_pairs,
                "RPE: every start pose instead of consecutive checkpoints");
  cmd->add_flag("--rpe-pairs-from-reference", args->rpe_pairs_from_reference,
                "RPE: choose pairs on the GT path instead of the estimate's");
  cmd->add_flag("--kitti-drift", args->kitti_drift,
                "KITTI devkit drift over 100..800 m segments (t_rel %, r_rel deg/100m)");
  cmd->add_option("--json", args->json, "Write the statistics as JSON");
  cmd->add_option("--plot", args->plot, "Write a PNG: top view and APE over time (matplotlib)");
  cmd->add_option("--also-est", args->also_est,
                  "Another estimate to draw in --plot, evaluated with the same options "
                  "(repeatable; printed to the log, not the table)")
      ->allow_extra_args(false);
  return [args] { return Run(*args); };
});

}  // namespace
}  // namespace planeloc::cli
