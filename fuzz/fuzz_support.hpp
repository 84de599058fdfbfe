// Shared by the fuzz targets: inputs become files in a private scratch folder, because antpose's
// readers take paths (their checks of what a path names are part of what is fuzzed).
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "antpose/core/error.hpp"

namespace antpose::fuzz {

/// A folder of this process, made on first use: each input overwrites its files.
inline const std::filesystem::path& scratch() {
  static const std::filesystem::path dir = [] {
    auto d = std::filesystem::temp_directory_path() / ("antpose-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

inline std::filesystem::path write(const std::filesystem::path& relative, std::string_view bytes) {
  const auto file = scratch() / relative;
  std::filesystem::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary | std::ios::trunc)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return file;
}

inline std::string_view view(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

/// Runs `f`, accepting what antpose promises for bad input: an antpose::Error (InputError,
/// MeasurementError) with a message. Anything else escapes and libFuzzer reports it as a crash.
template <class F>
void expect_clean(F&& f) {
  try {
    f();
  } catch (const Error& e) {
    if (std::string_view(e.what()).empty()) __builtin_trap();  // an error must say something
  }
}

}  // namespace antpose::fuzz
