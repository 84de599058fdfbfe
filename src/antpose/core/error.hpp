// Typed errors and warnings for everything a user can hand to antpose.
//
// An InputError always names the file (and the 1-based line when one applies), the
// offending value and what was expected, so that the CLI can print it verbatim.
#pragma once

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace antpose {

/// Base of all antpose errors.
class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Bad user input: a file that is missing, unreadable or malformed, or a value out of range.
class InputError : public Error {
 public:
  /// `line` is 1-based; 0 means "the whole file".
  InputError(std::filesystem::path file, std::size_t line, const std::string& message);
  InputError(std::filesystem::path file, const std::string& message) : InputError(std::move(file), 0, message) {}

  const std::filesystem::path& file() const { return file_; }
  std::size_t line() const { return line_; }
  const std::string& detail() const { return detail_; }

 private:
  std::filesystem::path file_;
  std::size_t line_;
  std::string detail_;
};

/// An output that cannot be written where the command line asks (a folder, a full disk, a
/// folder without write permission): like bad input, it is fixed by changing the command.
class OutputError : public InputError {
 public:
  using InputError::InputError;
};

/// Data that is well-formed but does not allow the requested computation
/// (e.g. no static window in a contact capture).
class MeasurementError : public Error {
 public:
  using Error::Error;
};

/// "file:line: message" (or "file: message" when line is 0).
std::string format_location(const std::filesystem::path& file, std::size_t line, const std::string& message);

/// A safe repair or a doubt about the input. Collected, never thrown.
struct Warning {
  std::filesystem::path file;  // may be empty when not tied to a file
  std::size_t line = 0;
  std::string message;

  std::string to_string() const;
};

/// Collects warnings while a stage runs; the caller decides how to show them.
class Diagnostics {
 public:
  void warn(std::filesystem::path file, std::size_t line, std::string message);
  void warn(std::string message) { warn({}, 0, std::move(message)); }

  const std::vector<Warning>& warnings() const { return warnings_; }
  bool empty() const { return warnings_.empty(); }
  /// True when any warning message contains `needle` (for tests and quality flags).
  bool mentions(const std::string& needle) const;

 private:
  std::vector<Warning> warnings_;
};

}  // namespace antpose
