#include "commands.hpp"

namespace antpose::cli {

// Placeholder until the contact verb lands.
void add_contact_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("contact", "(not yet available)");
  cmd->callback([] { throw Error("'contact' is not available in this build yet"); });
}

}  // namespace antpose::cli
