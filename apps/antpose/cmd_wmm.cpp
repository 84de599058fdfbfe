#include "commands.hpp"

namespace antpose::cli {

// Placeholder until the wmm verb lands.
void add_wmm_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("wmm", "(not yet available)");
  cmd->callback([] { throw Error("'wmm' is not available in this build yet"); });
}

}  // namespace antpose::cli
