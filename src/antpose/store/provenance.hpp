// What produced a result: which antpose, from which inputs (by content), for which device and
// site, when and how. Every JSON result and report carries it, so that a number found in a file
// months later can be traced to the data and the software behind it.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "antpose/io/capture.hpp"

namespace antpose::store {

/// One input by content: a file's SHA-256, a folder's content_digest.
struct InputDigest {
  std::string role;    // "capture", "device profile", "model", …
  std::string path;    // as given
  std::string sha256;  // content_digest
};

struct Provenance {
  std::string antpose;      // version_string(): release and git revision
  std::string created_utc;  // when the result was made
  std::string command;      // the verb ("measure", "calibrate joint")
  std::vector<InputDigest> inputs;
  std::optional<std::string> device_id;
  std::optional<std::string> device_profile_sha256;  // of the profile's YAML as used
  std::optional<Site> site;
  nlohmann::json options = nlohmann::json::object();  // the options as given, by name

  /// A record of `command` made now by this antpose.
  static Provenance now(std::string command);
  /// Adds `path` (a file or a folder) as an input of `role`, identified by its content.
  Provenance& input(std::string role, const std::filesystem::path& path);
};

nlohmann::json to_json(const Provenance& p);

}  // namespace antpose::store
