// planeloc: stereo camera localization in a prior LiDAR plane map.
// Owns the error boundary: the library throws, this file decides exit codes.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <exception>
#include <map>

#include "command_registry.h"
#include "planeloc/util/error.h"

int main(int argc, char** argv) {
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
