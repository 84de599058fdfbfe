#include "cli_provenance.hpp"

#include "antpose/store/content_hash.hpp"
#include "antpose/store/device_profile.hpp"

namespace antpose::cli {

store::Provenance provenance_of(const CLI::App& verb) {
  std::string command = verb.get_name();
  for (const CLI::App* up = verb.get_parent(); up != nullptr && up->get_parent() != nullptr; up = up->get_parent())
    command = up->get_name() + " " + command;
  store::Provenance p = store::Provenance::now(command);
  for (const CLI::Option* option : verb.get_options()) {
    if (option->count() == 0 || option->get_name() == "--help") continue;
    const auto& given = option->results();
    p.options[option->get_name()] = given.size() == 1 ? nlohmann::json(given.front()) : nlohmann::json(given);
  }
  return p;
}

void add_device(store::Provenance& provenance, const store::DeviceRef& device) {
  provenance.device_id = device.profile.id;
  provenance.device_profile_sha256 = store::sha256_bytes(store::format_device_profile(device.profile));
  if (device.file) provenance.input("device profile", *device.file);
}

}  // namespace antpose::cli
