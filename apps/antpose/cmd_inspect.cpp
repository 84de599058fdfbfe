// antpose inspect CAPTURE: what a capture holds (streams, rates, gaps, statistics, shots, truth).
#include <memory>
#include <string>

#include <fmt/format.h>

#include "antpose/io/import.hpp"
#include "antpose/io/inspect.hpp"
#include "antpose/io/text_file.hpp"
#include "cli_provenance.hpp"
#include "commands.hpp"
#include "json_output.hpp"

namespace antpose::cli {

namespace {

struct InspectOptions {
  std::string capture;
  std::string json;
  bool no_unit_repair = false;
};

void run_inspect(const InspectOptions& o, const CLI::App& verb) {
  Diagnostics diagnostics;
  CaptureReadOptions read_options;
  read_options.repair_units = !o.no_unit_repair;
  const CaptureFormat format = detect_capture_format(o.capture);
  const Capture capture = import_capture(o.capture, diagnostics, read_options);
  CaptureSummary summary = summarize(capture, read_options.gap_factor);
  summary.format = std::string(to_string(format));
  print_warnings(diagnostics);
  fmt::print("{}", format_summary(summary));
  if (!o.json.empty()) {
    store::Provenance provenance = provenance_of(verb).input("capture", o.capture);
    provenance.site = capture.site;
    write_json(o.json, to_json(summary), provenance);
  }
}

}  // namespace

void add_inspect_command(CLI::App& app) {
  auto opts = std::make_shared<InspectOptions>();
  auto* cmd = app.add_subcommand("inspect", "Summarize a capture: streams, rates, jitter, gaps, statistics, shots, truth");
  cmd->add_option("CAPTURE", opts->capture, "Capture folder or export (any layout convert reads)")->required();
  add_json_option(cmd, opts->json, "also write the summary");
  cmd->add_flag("--no-unit-repair", opts->no_unit_repair, "Refuse streams in the wrong unit instead of converting them");
  cmd->callback([opts, cmd] { run_inspect(*opts, *cmd); });
}

}  // namespace antpose::cli
