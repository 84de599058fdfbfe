// antpose convert IN OUT: any readable capture layout → native capture folder.
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "antpose/io/import.hpp"
#include "commands.hpp"

namespace antpose::cli {

namespace {

struct ConvertOptions {
  std::string in, out;
  bool no_unit_repair = false;
  bool gzip = false;
  bool force = false;
};

void run_convert(const ConvertOptions& o) {
  namespace fs = std::filesystem;
  if (fs::exists(o.out) && !o.force)
    throw InputError(o.out, "already exists; choose a new output folder or pass --force to replace it");
  Diagnostics diagnostics;
  CaptureReadOptions read_options;
  read_options.repair_units = !o.no_unit_repair;
  const CaptureFormat format = detect_capture_format(o.in);
  Capture capture = import_capture(o.in, diagnostics, read_options);
  if (o.gzip)
    for (auto& [name, s] : capture.streams) s.gzip = true;
  print_warnings(diagnostics);
  write_capture(capture, o.out, CaptureWriteOptions{.overwrite = o.force});
  std::size_t samples = 0;
  for (const auto& [name, s] : capture.streams) samples += s.size();
  fmt::print("converted {} capture {} → {}: {} streams ({} samples), {} shots\n", to_string(format), o.in, o.out,
             capture.streams.size(), samples, capture.shots.size());
}

}  // namespace

void add_convert_command(CLI::App& app) {
  auto opts = std::make_shared<ConvertOptions>();
  auto* cmd = app.add_subcommand("convert", "Import a capture (native, thesis project, Sensor Logger, phyphox) into a native capture folder");
  cmd->add_option("IN", opts->in, "Input capture folder or export")->required();
  cmd->add_option("OUT", opts->out, "Output capture folder (must not exist unless --force)")->required();
  cmd->add_flag("--no-unit-repair", opts->no_unit_repair, "Refuse streams in the wrong unit instead of converting them");
  cmd->add_flag("--gzip", opts->gzip, "Write the sensor streams as .csv.gz");
  cmd->add_flag("--force", opts->force, "Replace OUT if it exists (only after the new capture is complete)");
  cmd->callback([opts] { run_convert(*opts); });
}

}  // namespace antpose::cli
