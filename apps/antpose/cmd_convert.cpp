#include "commands.hpp"

namespace antpose::cli {

// Placeholder until the convert verb lands.
void add_convert_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("convert", "(not yet available)");
  cmd->callback([] { throw Error("'convert' is not available in this build yet"); });
}

}  // namespace antpose::cli
