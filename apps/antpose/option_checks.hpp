// Checks of option values that several verbs share, made while the command line is parsed so
// that a bad value is named before any work (exit 2).
#pragma once

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace antpose::cli {

/// A CLI11 check that a number is finite and within [lo, hi] (CLI::Range lets NaN through).
CLI::Validator finite_within(double lo, double hi, const std::string& unit);

/// The non-empty items of a comma-separated option value ("a,b,,c" → a, b, c).
std::vector<std::string> split_list(const std::string& text);

/// Adds the hidden option `old_name` that refuses to run and names `new_name` instead, so a
/// script written for an older antpose fails with a message instead of doing something else.
void add_renamed_option(CLI::App& cmd, const std::string& old_name, const std::string& new_name);

/// How a verb takes its orientation method.
struct OrientationMethodSettings {
  bool several = false;                  ///< a comma-separated list instead of one name
  std::vector<std::string> other_names;  ///< values that name something else of the verb (its solvers)
  std::string other_hint;                ///< what to answer when one of those is given
};

/// The option that names the orientation method, `--method` on every verb that has one; each
/// name is checked against the estimators while the command line is parsed.
CLI::Option* add_orientation_method_option(CLI::App& cmd, std::string& value, const std::string& help,
                                           const OrientationMethodSettings& settings = {});

}  // namespace antpose::cli
