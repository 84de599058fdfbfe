// antpose device: the device database (docs/devices.md).
//   antpose device list [--db PATH]
//   antpose device show ID [--history] [--json FILE|-] [--db PATH]
//   antpose device export ID -o FILE.yaml [--force] [--db PATH]
//   antpose device import FILE.yaml [--id ID] [--model M] [--db PATH]
//   antpose device remove ID [--db PATH]
#include <filesystem>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/store/device_db.hpp"
#include "cli_provenance.hpp"
#include "commands.hpp"
#include "json_output.hpp"

namespace antpose::cli {
namespace {
namespace fs = std::filesystem;

struct DeviceArgs {
  std::optional<std::string> db;
  std::string id, file, output, json;
  std::optional<std::string> import_id, model;
  bool history = false, force = false;

  std::optional<fs::path> db_path() const { return db ? std::optional<fs::path>(*db) : std::nullopt; }
};

store::DeviceDb open_db(const DeviceArgs& a, store::DeviceDb::Access access = store::DeviceDb::Access::kReadWrite) {
  return store::DeviceDb(store::DeviceDb::resolve_path(a.db_path()), access);
}

void run_list(const DeviceArgs& a) {
  const fs::path file = store::DeviceDb::resolve_path(a.db_path());
  if (!fs::exists(file)) {
    fmt::print("no devices: there is no device database at {} yet\n", file.string());
    return;
  }
  const store::DeviceDb db(file, store::DeviceDb::Access::kReadOnly);
  const auto devices = db.list_devices();
  if (devices.empty()) {
    fmt::print("no devices in {}\n", db.path().string());
    return;
  }
  fmt::print("{:<20} {:<24} {:<25} {}\n", "id", "model", "last calibration (UTC)", "calibrated");
  for (const auto& d : devices)
    fmt::print("{:<20} {:<24} {:<25} {}\n", d.id, d.model.empty() ? "-" : d.model,
               d.last_calibration_utc.value_or("-"), d.calibrated.empty() ? "-" : fmt::format("{}", fmt::join(d.calibrated, ", ")));
}

nlohmann::json run_json(const store::CalibrationRun& r) {
  return {{"run_id", r.run_id},     {"kind", r.kind},         {"started_utc", r.started_utc},
          {"finished_utc", r.finished_utc}, {"status", r.status}, {"settings", r.settings},
          {"inputs", r.inputs},     {"residuals", r.residuals}, {"message", r.message},
          {"profile_yaml", r.profile_yaml}};
}

void run_show(const DeviceArgs& a, const CLI::App& verb) {
  const store::DeviceDb db = open_db(a, store::DeviceDb::Access::kReadOnly);
  const store::DeviceProfile profile = db.profile(a.id);
  const std::string yaml = store::format_device_profile(profile);
  if (!a.json.empty()) {
    nlohmann::json j{{"id", profile.id}, {"model", profile.model}, {"profile_yaml", yaml}};
    if (a.history) {
      j["history"] = nlohmann::json::array();
      for (const auto& r : db.history(a.id)) j["history"].push_back(run_json(r));
    }
    store::Provenance provenance = provenance_of(verb).input("device database", db.path());
    provenance.device_id = profile.id;
    provenance.device_profile_sha256 = store::sha256_bytes(yaml);
    write_json(a.json, j, provenance);
    return;
  }
  fmt::print("{}", yaml);
  if (a.history) {
    fmt::print("\n# history of {}\n{:>6}  {:<11} {:<7} {:<25} {:>6}  {}\n", a.id, "run", "kind", "status", "finished (UTC)",
               "inputs", "message");
    for (const auto& r : db.history(a.id))
      fmt::print("{:>6}  {:<11} {:<7} {:<25} {:>6}  {}\n", r.run_id, r.kind, r.status, r.finished_utc,
                 r.inputs.is_array() ? r.inputs.size() : 0, r.message);
  }
}

void run_export(const DeviceArgs& a) {
  open_db(a, store::DeviceDb::Access::kReadOnly).export_profile(a.id, a.output, a.force);
  fmt::print("wrote {}\n", a.output);
}

void run_import(const DeviceArgs& a) {
  store::DeviceDb db = open_db(a);
  const auto run = db.import_profile(a.file, a.import_id, a.model);
  const std::string id = a.import_id ? *a.import_id : store::read_device_profile(a.file).id;
  fmt::print("imported {} as device '{}' (run {}) into {}\n", a.file, id, run, db.path().string());
}

void run_remove(const DeviceArgs& a) {
  open_db(a).remove_device(a.id);
  fmt::print("removed device '{}'\n", a.id);
}

void add_db_option(CLI::App* cmd, DeviceArgs& a) {
  cmd->add_option("--db", a.db, "device database (default: $ANTPOSE_DB, else $XDG_DATA_HOME/antpose/devices.sqlite, "
                                "else ~/.local/share/antpose/devices.sqlite)");
}

}  // namespace

void add_device_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("device", "device profiles in the device database (list, show, export, import)");
  cmd->require_subcommand(1);

  auto a = std::make_shared<DeviceArgs>();
  auto* list = cmd->add_subcommand("list", "devices: id, model, last calibration, what is calibrated");
  add_db_option(list, *a);
  list->callback([a] { run_list(*a); });

  auto* show = cmd->add_subcommand("show", "the current profile of a device (YAML), optionally its calibration history");
  show->add_option("id", a->id, "device id")->required();
  show->add_flag("--history", a->history, "also list the calibration runs");
  add_json_option(show, a->json, "write the profile (and --history) instead of printing YAML");
  add_db_option(show, *a);
  show->callback([a, show] { run_show(*a, *show); });

  auto* exp = cmd->add_subcommand("export", "write the current profile of a device as a YAML file");
  exp->add_option("id", a->id, "device id")->required();
  exp->add_option("-o,--output", a->output, "YAML file to write")->required();
  exp->add_flag("--force", a->force, "replace an existing file");
  add_db_option(exp, *a);
  exp->callback([a] { run_export(*a); });

  auto* imp = cmd->add_subcommand("import", "add or update a device from a YAML profile (recorded as an import run)");
  imp->add_option("file", a->file, "device YAML")->required()->check(CLI::ExistingFile);
  imp->add_option("--id", a->import_id, "device id (default: device.id of the file)");
  imp->add_option("--model", a->model, "device model (default: device.model of the file)");
  add_db_option(imp, *a);
  imp->callback([a] { run_import(*a); });

  auto* rm = cmd->add_subcommand("remove", "delete a device and its calibration history");
  rm->add_option("id", a->id, "device id")->required();
  add_db_option(rm, *a);
  rm->callback([a] { run_remove(*a); });
}

}  // namespace antpose::cli
