#include "progress.hpp"

#include <unistd.h>

#include <cstdio>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace antpose::cli {
namespace {

enum class ProgressMode { kAuto, kNone, kJson };
ProgressMode progress_mode = ProgressMode::kAuto;

bool on_terminal() { return progress_mode == ProgressMode::kAuto && ::isatty(STDERR_FILENO) == 1; }

}  // namespace

void add_progress_options(CLI::App& app) {
  static std::string choice = "auto";
  app.add_option("--progress", choice,
                 "progress of long verbs on stderr: auto (on a terminal only), none, json (one "
                 "JSON object per line, for wrappers)")
      ->check(CLI::IsMember({"auto", "none", "json"}))
      ->capture_default_str()
      ->each([](const std::string& v) {
        progress_mode = v == "json" ? ProgressMode::kJson : v == "none" ? ProgressMode::kNone : ProgressMode::kAuto;
      });
  app.add_flag_callback(
      "-q,--quiet", [] { progress_mode = ProgressMode::kNone; }, "no progress (warnings and errors are still printed)");
}

ProgressLine::ProgressLine(std::string task) : task_(std::move(task)), start_(std::chrono::steady_clock::now()) {}

ProgressLine::~ProgressLine() {
  if (open_line_) fmt::print(stderr, "\n");
}

std::function<void(const std::string&, int, int)> ProgressLine::callback() {
  if (progress_mode == ProgressMode::kNone || (progress_mode == ProgressMode::kAuto && !on_terminal())) return {};
  return [this](const std::string& stage, int done, int total) { report(stage, done, total); };
}

void ProgressLine::report(const std::string& stage, int done, int total) {
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (progress_mode == ProgressMode::kJson) {
    nlohmann::json j{{"elapsed_s", s}, {"stage", stage}, {"done", done}, {"total", total}};
    if (!task_.empty()) j["task"] = task_;
    fmt::print(stderr, "{}\n", j.dump());
  } else {
    fmt::print(stderr, "\r\033[K[{:5.1f} s] {}{} {}/{}", s, task_.empty() ? "" : task_ + ": ", stage, done, total);
    open_line_ = done < total;
    if (!open_line_) fmt::print(stderr, "\n");
  }
  std::fflush(stderr);
}

}  // namespace antpose::cli
