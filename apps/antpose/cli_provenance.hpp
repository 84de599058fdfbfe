// The provenance (store/provenance.hpp) of a verb's result, from its command line.
#pragma once

#include <CLI/CLI.hpp>

#include "antpose/store/device_ref.hpp"
#include "antpose/store/provenance.hpp"

namespace antpose::cli {

/// This antpose, now, the verb ("calibrate joint") and every option given to it, by name.
store::Provenance provenance_of(const CLI::App& verb);

/// The device: its id, the SHA-256 of its profile as used, and the profile file as an input.
void add_device(store::Provenance& provenance, const store::DeviceRef& device);

}  // namespace antpose::cli
