// Helpers shared by the tests: reference data, scratch folders and running the CLI.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <typeinfo>
#include <utility>

#include <gtest/gtest.h>

#include "antpose/core/error.hpp"

namespace antpose::test {

/// Path of `relative` inside ANTPOSE_SHARED_DIR (a CMake cache variable, default ../shared).
/// Throws with a clear message when the shared folder or the file is missing, which fails the
/// test that needed it.
std::filesystem::path shared_path(std::string_view relative);

/// Path inside the source tree (examples/, data/).
std::filesystem::path source_path(std::string_view relative);

/// A fresh empty folder, removed with its contents when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(std::string_view name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// Writes a text file (creating folders).
void write_file(const std::filesystem::path& file, std::string_view content);

/// A valid 64×48 grey JPEG whose frame header (SOF0) claims `width`×`height` px.
std::string jpeg_claiming(int width, int height);

struct CliResult {
  int status = 0;
  std::string out;  // stdout
  std::string err;  // stderr
};

/// Runs the antpose executable with the given argument string (shell syntax).
CliResult run_cli(const std::string& args);

/// As run_cli, but without the privilege to write where the file permissions forbid it: as
/// nobody (setpriv) when the tests run as root, who may write anywhere.
CliResult run_cli_unprivileged(const std::string& args);

/// The antpose executable the tests run (for scripts that take it).
std::filesystem::path cli_path();

/// The message of the `E` that `f` throws; fails the calling test when it throws none.
template <class E, class F>
std::string error_message(F&& f) {
  try {
    f();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "no " << typeid(E).name() << " thrown";
  return "";
}

/// The message of the InputError that `f` throws; fails the calling test when it throws none.
template <class F>
std::string input_error(F&& f) {
  return error_message<InputError>(std::forward<F>(f));
}

}  // namespace antpose::test
