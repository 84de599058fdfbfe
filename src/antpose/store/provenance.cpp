#include "antpose/store/provenance.hpp"

#include "antpose/store/content_hash.hpp"
#include "antpose/version.hpp"

namespace antpose::store {

Provenance Provenance::now(std::string command) {
  Provenance p;
  p.antpose = version_string();
  p.created_utc = utc_now();
  p.command = std::move(command);
  return p;
}

Provenance& Provenance::input(std::string role, const std::filesystem::path& path) {
  inputs.push_back({std::move(role), path.string(), content_digest(path)});
  return *this;
}

nlohmann::json to_json(const Provenance& p) {
  nlohmann::json j{{"antpose", p.antpose}, {"created_utc", p.created_utc}, {"command", p.command}};
  j["inputs"] = nlohmann::json::array();
  for (const auto& i : p.inputs) j["inputs"].push_back({{"role", i.role}, {"path", i.path}, {"sha256", i.sha256}});
  j["device"] = p.device_id ? nlohmann::json{{"id", *p.device_id}, {"profile_sha256", p.device_profile_sha256.value_or("")}}
                            : nlohmann::json();
  j["site"] = p.site ? nlohmann::json{{"lat_deg", p.site->lat_deg}, {"lon_deg", p.site->lon_deg},
                                      {"alt_m", p.site->alt_m}, {"date", p.site->date}}
                     : nlohmann::json();
  j["options"] = p.options;
  return j;
}

}  // namespace antpose::store
