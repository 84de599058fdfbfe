// The --json option every verb shares: a file, or '-' for standard output.
#pragma once

#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "antpose/store/provenance.hpp"

namespace antpose::cli {

/// Adds `--json FILE|-` to `cmd`. With '-' the JSON goes to standard output and standard output
/// carries nothing else: from the moment the option is parsed, whatever the verb prints there
/// goes to standard error instead, so `antpose … --json - | jq` always parses.
CLI::Option* add_json_option(CLI::App* cmd, std::string& target, const std::string& what);

/// Writes `j` with its "provenance" to the --json target (io::write_text_atomic's contract for a
/// file); nothing when `target` is empty.
void write_json(const std::string& target, nlohmann::json j, const store::Provenance& provenance);

}  // namespace antpose::cli
