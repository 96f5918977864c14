#include "command_registry.h"

namespace planeloc::cli {

std::vector<CommandEntry>& CommandRegistry() {
  static std::vector<CommandEntry> registry;
  return registry;
}

CommandRegistrar::CommandRegistrar(std::string name, CommandSetup setup) {
  CommandRegistry().push_back({std::move(name), std::move(setup)});
}

}  // namespace planeloc::cli
