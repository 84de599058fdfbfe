// yaml-cpp helpers for antpose's own YAML files (device profiles, boards, simulated truth):
// every read names the file, the 1-based line and the key of a bad value, and what was
// expected (InputError); numbers are written with io::format_number (round-trip digits).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include <yaml-cpp/yaml.h>

#include "antpose/core/error.hpp"
#include "antpose/geometry/rotation.hpp"

namespace antpose::io {

/// 1-based line of a node (0 when unknown, e.g. a missing key).
std::size_t line_of(const YAML::Node& node);
/// "'value'", "a list of N", "a map" or "empty", for messages.
std::string show(const YAML::Node& node);
/// Parses YAML text; InputError with the line for a syntax error.
YAML::Node load_yaml(const std::string& text, const std::filesystem::path& file);

/// A finite number; `key` names the value in the message.
double yaml_number(const YAML::Node& node, const std::filesystem::path& file, const std::string& key);
/// An integer.
long long yaml_integer(const YAML::Node& node, const std::filesystem::path& file, const std::string& key);
/// A scalar string.
std::string yaml_string(const YAML::Node& node, const std::filesystem::path& file, const std::string& key);
/// [x, y, z].
Vec3 yaml_vec3(const YAML::Node& node, const std::filesystem::path& file, const std::string& key);
/// [[..], [..], [..]] (rows).
Mat3 yaml_mat3(const YAML::Node& node, const std::filesystem::path& file, const std::string& key);
/// parent[key] when it is a map or missing (a null node); InputError when present but not a map.
YAML::Node yaml_section(const YAML::Node& parent, const char* key, const std::filesystem::path& file,
                        const std::string& path);
/// parent[key], InputError naming the key when missing.
YAML::Node yaml_required(const YAML::Node& parent, const char* key, const std::filesystem::path& file,
                         const std::string& path);

/// A number with round-trip digits, and flow-style sequences of them.
YAML::Node yaml_scalar(double v);
YAML::Node yaml_flow_vector(const Vec3& v);
YAML::Node yaml_flow_matrix(const Mat3& m);
/// A node emitted as a YAML document, with its final newline.
std::string yaml_document(const YAML::Node& node);

}  // namespace antpose::io
