#include "antpose/io/yaml_util.hpp"

#include <cmath>

#include <fmt/format.h>

#include "antpose/io/csv.hpp"

namespace antpose::io {
namespace fs = std::filesystem;

std::size_t line_of(const YAML::Node& node) {
  return node.Mark().is_null() ? 0 : static_cast<std::size_t>(node.Mark().line) + 1;
}

std::string show(const YAML::Node& node) {
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return fmt::format("a list of {}", node.size());
  if (node.IsMap()) return "a map";
  return "empty";
}

YAML::Node load_yaml(const std::string& text, const fs::path& file) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(file, e.mark.is_null() ? 0 : static_cast<std::size_t>(e.mark.line) + 1, "not valid YAML: " + e.msg);
  }
}

double yaml_number(const YAML::Node& node, const fs::path& file, const std::string& key) {
  double v = 0.0;
  try {
    v = node.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(file, line_of(node), fmt::format("{}: {} is not a number", key, show(node)));
  }
  if (!std::isfinite(v)) throw InputError(file, line_of(node), fmt::format("{}: {} is not a finite number", key, show(node)));
  return v;
}

long long yaml_integer(const YAML::Node& node, const fs::path& file, const std::string& key) {
  try {
    return node.as<long long>();
  } catch (const YAML::Exception&) {
    throw InputError(file, line_of(node), fmt::format("{}: {} is not an integer", key, show(node)));
  }
}

std::string yaml_string(const YAML::Node& node, const fs::path& file, const std::string& key) {
  if (!node.IsScalar()) throw InputError(file, line_of(node), fmt::format("{} is {}, expected a text value", key, show(node)));
  return node.Scalar();
}

Vec3 yaml_vec3(const YAML::Node& node, const fs::path& file, const std::string& key) {
  if (!node.IsSequence() || node.size() != 3)
    throw InputError(file, line_of(node), fmt::format("{} is {}, expected a list of 3 numbers [x, y, z]", key, show(node)));
  Vec3 v;
  for (std::size_t k = 0; k < 3; ++k)
    v[static_cast<Eigen::Index>(k)] = yaml_number(node[k], file, fmt::format("{}[{}]", key, k));
  return v;
}

Mat3 yaml_mat3(const YAML::Node& node, const fs::path& file, const std::string& key) {
  if (!node.IsSequence() || node.size() != 3)
    throw InputError(file, line_of(node),
                     fmt::format("{} is {}, expected 3 rows of 3 numbers [[..], [..], [..]]", key, show(node)));
  Mat3 M;
  for (std::size_t r = 0; r < 3; ++r)
    M.row(static_cast<Eigen::Index>(r)) = yaml_vec3(node[r], file, fmt::format("{}[{}]", key, r)).transpose();
  return M;
}

YAML::Node yaml_section(const YAML::Node& parent, const char* key, const fs::path& file, const std::string& path) {
  YAML::Node node = parent[key];
  if (node && !node.IsMap()) throw InputError(file, line_of(node), fmt::format("'{}' is {}, expected a map", path, show(node)));
  return node;
}

YAML::Node yaml_required(const YAML::Node& parent, const char* key, const fs::path& file, const std::string& path) {
  YAML::Node node = parent[key];
  if (!node) throw InputError(file, line_of(parent), fmt::format("'{}' is missing", path));
  return node;
}

YAML::Node yaml_scalar(double v) { return YAML::Node(format_number(v)); }

std::string yaml_document(const YAML::Node& node) {
  YAML::Emitter out;
  out << node;
  return std::string(out.c_str()) + "\n";
}

YAML::Node yaml_flow_vector(const Vec3& v) {
  YAML::Node n(YAML::NodeType::Sequence);
  for (int k = 0; k < 3; ++k) n.push_back(format_number(v[k]));
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}

YAML::Node yaml_flow_matrix(const Mat3& M) {
  YAML::Node n(YAML::NodeType::Sequence);
  for (int r = 0; r < 3; ++r) n.push_back(yaml_flow_vector(M.row(r).transpose()));
  return n;
}

}  // namespace antpose::io
