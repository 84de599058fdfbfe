#include "antpose/io/import_detail.hpp"

#include <algorithm>
#include <cctype>

namespace antpose::io::detail {

YAML::Node SourceRecord::to_yaml() const {
  YAML::Node n;
  n["format"] = format;
  n["path"] = path.string();
  for (const auto& r : read) n["read"].push_back(r);
  for (const auto& s : skipped) n["skipped"].push_back(s);
  for (const auto& a : assumptions) n["assumptions"].push_back(a);
  if (extra.IsMap())
    for (const auto& kv : extra) n[kv.first.as<std::string>()] = kv.second;
  return n;
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

std::string rel_name(const std::filesystem::path& file, const std::filesystem::path& folder) {
  const auto rel = file.lexically_relative(folder);
  return rel.empty() || rel.string().starts_with("..") ? file.string() : rel.generic_string();
}

Stream make_stream(std::string name, std::vector<std::string> columns, std::vector<double> t,
                   const std::vector<std::vector<double>>& values) {
  Stream s;
  s.name = std::move(name);
  s.columns = std::move(columns);
  s.values.resize(static_cast<Eigen::Index>(t.size()), static_cast<Eigen::Index>(s.columns.size()));
  for (std::size_t k = 0; k < values.size(); ++k)
    for (std::size_t i = 0; i < t.size(); ++i) s.values(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) = values[k][i];
  s.t = std::move(t);
  return s;
}

}  // namespace antpose::io::detail
