// Self-registering subcommands of the `planeloc` CLI.
//
// Each apps/cmd_<name>.cc defines a static CommandRegistrar whose `setup` adds a CLI11
// subcommand and returns the function that runs it. main.cc parses, dispatches and owns error
// handling: planeloc::InputError -> one message, exit 2; any other exception -> exit 1.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace planeloc::cli {

// Returns the process exit code (0 on success).
using CommandRunner = std::function<int()>;
// Adds the subcommand to `app` and returns the runner to call if it was chosen.
using CommandSetup = std::function<CommandRunner(CLI::App& app)>;

struct CommandEntry {
  std::string name;  // sort key: the order of subcommands in --help
  CommandSetup setup;
};

std::vector<CommandEntry>& CommandRegistry();

struct CommandRegistrar {
  CommandRegistrar(std::string name, CommandSetup setup);
};

}  // namespace planeloc::cli
