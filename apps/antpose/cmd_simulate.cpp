#include "commands.hpp"

namespace antpose::cli {

// Placeholder until the simulate verb lands.
void add_simulate_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("simulate", "(not yet available)");
  cmd->callback([] { throw Error("'simulate' is not available in this build yet"); });
}

}  // namespace antpose::cli
