#include "json_output.hpp"

#include <unistd.h>

#include <cstdio>

#include "antpose/io/text_file.hpp"

namespace antpose::cli {
namespace {

// The descriptor that was standard output before '-' claimed it for the JSON, or -1.
int json_descriptor = -1;

void claim_standard_output() {
  if (json_descriptor >= 0) return;
  std::fflush(stdout);
  json_descriptor = ::dup(STDOUT_FILENO);
  if (json_descriptor < 0 || ::dup2(STDERR_FILENO, STDOUT_FILENO) < 0)
    throw OutputError("-", "cannot set standard output aside for the JSON");
}

}  // namespace

CLI::Option* add_json_option(CLI::App* cmd, std::string& target, const std::string& what) {
  return cmd->add_option("--json", target, what + " as JSON to this file, or to standard output for '-'")
      ->type_name("FILE|-")
      ->each([](const std::string& value) {
        if (value == "-") claim_standard_output();
      });
}

void write_json(const std::string& target, nlohmann::json j, const store::Provenance& provenance) {
  if (target.empty()) return;
  j["provenance"] = store::to_json(provenance);
  const std::string text = j.dump(2) + "\n";
  if (target == "-")
    io::write_descriptor(json_descriptor, text, "-");
  else
    io::write_text_atomic(target, text);
}

}  // namespace antpose::cli
