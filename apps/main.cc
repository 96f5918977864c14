// planeloc: stereo camera localization in a prior LiDAR plane map.
// Owns the error boundary: the library throws, this file decides exit codes.
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <map>

#include "command_registry.h"
#include "planeloc/util/error.h"

int main(int argc, char** argv) {
  // Logs and warnings go to stderr (spdlog's default logger writes to stdout): stdout carries only
  // the machine-readable outputs documented as such (the `eval` table).
  spdlog::set_default_logger(spdlog::stderr_color_mt("planeloc"));
  CLI::App app{"planeloc: stereo camera localization in a prior LiDAR plane map"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "planeloc 0.1.0");
  bool verbose = false;
  app.add_flag("-v,--verbose", verbose, "Debug logging");

  auto& registry = planeloc::cli::CommandRegistry();
  std::sort(registry.begin(), registry.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  std::map<std::string, planeloc::cli::CommandRunner> runners;
  for (const auto& entry : registry) runners[entry.name] = entry.setup(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // A first word that is no subcommand: name it (CLI11 says only "A subcommand is required").
    if (argc > 1 && argv[1][0] != '-' && runners.count(argv[1]) == 0) {
      std::string names;
      for (const auto& entry : registry) names += (names.empty() ? "" : ", ") + entry.name;
      std::fprintf(
          stderr,
          "planeloc: error: unknown subcommand '%s' (fix: use one of %s; see planeloc --help)\n",
          argv[1], names.c_str());
      return 2;
    }
    // CLI11 returns 0 for --help/--version; usage errors are the user's: exit 2.
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  spdlog::set_level(verbose ? spdlog::level::debug : spdlog::level::info);
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");

  try {
    for (const auto* sub : app.get_subcommands()) {
      const auto it = runners.find(sub->get_name());
      if (it != runners.end()) return it->second();
    }
    std::fprintf(stderr, "planeloc: no subcommand given (see planeloc --help)\n");
    return 2;
  } catch (const planeloc::InputError& e) {
    std::fprintf(stderr, "planeloc: error: %s\n", e.what());
    return 2;
  } catch (const planeloc::OptionsError& e) {
    std::fprintf(stderr, "planeloc: invalid option: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "planeloc: internal error: %s\n", e.what());
    return 1;
  }
}
