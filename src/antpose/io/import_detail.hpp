// Shared pieces of the importers (not part of the public API).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "antpose/io/capture.hpp"

namespace antpose::io::detail {

/// What an importer read and assumed; becomes capture.yaml `source:`.
struct SourceRecord {
  std::string format;                    // e.g. "sensor-logger"
  std::filesystem::path path;            // the input folder
  std::vector<std::string> read;         // "Accelerometer.csv → accelerometer (2908 rows)"
  std::vector<std::string> skipped;      // "Pedometer.csv: step counts, not used"
  std::vector<std::string> assumptions;  // units, sign conventions, gravity
  YAML::Node extra;                      // app version, device details, ...

  YAML::Node to_yaml() const;
};

/// Lower-case ASCII copy.
std::string lower(std::string s);

/// Relative name for messages and the source record ("Accelerometer.csv", "meta/time.csv").
std::string rel_name(const std::filesystem::path& file, const std::filesystem::path& folder);

/// Builds a stream from columns of equal length.
Stream make_stream(std::string name, std::vector<std::string> columns, std::vector<double> t,
                   const std::vector<std::vector<double>>& columns_values);

}  // namespace antpose::io::detail
