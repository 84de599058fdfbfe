// Progress of long verbs: one style, on a terminal only, silenced by --quiet, and as JSON lines
// for wrappers with --progress json.
#pragma once

#include <chrono>
#include <functional>
#include <string>

#include <CLI/CLI.hpp>

namespace antpose::cli {

/// Adds the global --quiet and --progress auto|none|json options to the program. auto (the
/// default) draws a line on standard error when it is a terminal and nothing otherwise, so a
/// log file never receives carriage returns or escape sequences.
void add_progress_options(CLI::App& app);

/// Reports "stage done/total" for one task (a site, a measurement).
class ProgressLine {
 public:
  /// `task` prefixes each line ("site-12: "); empty for the verb's single task.
  explicit ProgressLine(std::string task = {});
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  /// The callback to hand to the library; empty when progress is off.
  std::function<void(const std::string& stage, int done, int total)> callback();

 private:
  void report(const std::string& stage, int done, int total);
  std::string task_;
  std::chrono::steady_clock::time_point start_;
  bool open_line_ = false;  // a terminal line drawn and not yet ended
};

}  // namespace antpose::cli
