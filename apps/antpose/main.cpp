// antpose <verb> ...: entry point. The exit status is the contract of README "Exit codes":
// 0 every requested result is usable, 2 bad input (or an output that cannot be written),
// 3 the data cannot support the measurement, 4 results written but some unusable,
// 1 an internal fault (a bug to report, or the machine out of memory).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <new>

#include <fmt/core.h>

#include "antpose/core/allocator.hpp"
#include "antpose/version.hpp"
#include "commands.hpp"
#include "progress.hpp"

namespace antpose::cli {

void print_warnings(const Diagnostics& diagnostics) {
  for (const auto& w : diagnostics.warnings()) fmt::print(stderr, "warning: {}\n", w.to_string());
}

namespace {

// Levenshtein distance, for "did you mean".
std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// InputError for a first word that is not a verb, naming the closest verb and all of them.
void check_verb(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return;
  const std::string word = argv[1];
  std::string closest, all;
  std::size_t best = 3;  // suggest only a verb within two edits
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    const std::string& name = sub->get_name();
    if (name == word) return;
    all += (all.empty() ? "" : ", ") + name;
    if (const std::size_t d = edit_distance(word, name); d < best) best = d, closest = name;
  }
  throw InputError({}, fmt::format("unknown verb '{}'{}; the verbs are {}", word,
                                   closest.empty() ? "" : fmt::format(" (did you mean '{}'?)", closest), all));
}

int report_error(const char* what, int status) {
  fmt::print(stderr, "error: {}\n", what);
  return status;
}

}  // namespace
}  // namespace antpose::cli

int main(int argc, char** argv) {
  using namespace antpose::cli;
  antpose::tune_allocator();  // before any work: see core/allocator.hpp
  CLI::App app{"antpose: antenna azimuth, downtilt and roll from a smartphone"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "antpose " + antpose::version_string());
  app.footer(kExitStatusHelp);
  app.fallthrough();  // the global options (--quiet, --progress) may follow the verb
  add_progress_options(app);
  add_convert_command(app);
  add_inspect_command(app);
  add_wmm_command(app);
  add_contact_command(app);
  add_measure_command(app);
  add_simulate_command(app);
  add_bench_command(app);
  add_orientation_command(app);
  add_calibrate_command(app);
  add_device_command(app);
  try {
    check_verb(app, argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::RuntimeError& e) {
    return e.get_exit_code();  // a verb's own status; it has printed why
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);  // prints --help, --version or the misuse
    return status == 0 ? kExitOk : kExitBadInput;
  } catch (const antpose::InputError& e) {  // OutputError too
    return report_error(e.what(), kExitBadInput);
  } catch (const antpose::MeasurementError& e) {
    return report_error(e.what(), kExitUnsupported);
  } catch (const std::filesystem::filesystem_error& e) {  // a path the checks did not reach: still the input
    return report_error(e.what(), kExitBadInput);
  } catch (const std::bad_alloc&) {
    return report_error("out of memory", kExitInternal);
  } catch (const std::exception& e) {
    return report_error(fmt::format("internal fault, please report it: {}", e.what()).c_str(), kExitInternal);
  }
  return kExitOk;
}
