#include "commands.hpp"

namespace antpose::cli {

// Placeholder until the inspect verb lands.
void add_inspect_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("inspect", "(not yet available)");
  cmd->callback([] { throw Error("'inspect' is not available in this build yet"); });
}

}  // namespace antpose::cli
