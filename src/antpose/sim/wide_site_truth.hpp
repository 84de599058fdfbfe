// The keys a wide antenna site adds to truth/scene.yaml (docs/simulator.md): every drawn
// parameter, so that a failure can be traced to what made the site hard.
#pragma once

#include <yaml-cpp/yaml.h>

#include "antpose/sim/capture_simulator.hpp"

namespace antpose::sim {

/// Adds `distribution: wide`, photo, light, background, arrangement (with the frame's struts),
/// metal_albedo and walk to `root`, and to each antenna node root["antennas"][k] the rendered
/// panel's bracket position and end caps (under panel), its finish, mount, roi_margin_fraction
/// and width_px. `truth.wide` must be set.
void add_wide_site_truth(YAML::Node& root, const AntennaTruth& truth);

}  // namespace antpose::sim
