#include "antpose/sim/wide_site_truth.hpp"

#include <array>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "antpose/io/csv.hpp"
#include "antpose/io/yaml_util.hpp"

namespace antpose::sim {

namespace {

using io::yaml_flow_vector;
using io::yaml_scalar;

template <typename Range>
YAML::Node flow_list(const Range& values) {
  YAML::Node n;
  for (const double v : values) n.push_back(io::format_number(v));
  n.SetStyle(YAML::EmitterStyle::Flow);
  return n;
}

YAML::Node photo_node(const PhotoDraw& p) {
  YAML::Node n;
  n["scale"] = yaml_scalar(p.scale);
  YAML::Node size;
  size.push_back(p.camera.width);
  size.push_back(p.camera.height);
  size.SetStyle(YAML::EmitterStyle::Flow);
  n["size_px"] = size;
  n["megapixels"] = yaml_scalar(p.camera.width * static_cast<double>(p.camera.height) / 1e6);
  n["jpeg_quality"] = p.jpeg_quality;
  n["blur_sigma_px"] = yaml_scalar(p.blur_sigma_px);
  n["noise_scale"] = yaml_scalar(p.noise_scale);
  n["exposure_s"] = yaml_scalar(p.exposure_s);
  return n;
}

YAML::Node light_node(const SiteLight& s) {
  YAML::Node n;
  n["mode"] = to_string(s.mode);
  n["sun_elevation_deg"] = yaml_scalar(rad2deg(s.sun_elevation));
  n["sun_azimuth_magnetic_deg"] = yaml_scalar(rad2deg(s.sun_azimuth));
  n["towards_sun_world"] = yaml_flow_vector(towards_sun(s));
  n["ambient"] = yaml_scalar(s.ambient);
  n["direct"] = yaml_scalar(s.direct);
  n["sky_zenith"] = yaml_scalar(s.sky_zenith);
  n["sky_horizon"] = yaml_scalar(s.sky_horizon);
  n["cloud_contrast"] = yaml_scalar(s.cloud_contrast);
  n["sensor_gain"] = yaml_scalar(s.gain);
  return n;
}

YAML::Node background_node(const Background& bg) {
  YAML::Node n;
  n["kind"] = to_string(bg.kind);
  for (std::size_t k = 0; k < bg.buildings.size(); ++k) {
    const Building& b = bg.buildings[k];
    YAML::Node m;
    m["name"] = fmt::format("building-{}", k + 1);
    m["centre_m"] = yaml_flow_vector(Vec3(b.centre_xy.x(), b.centre_xy.y(), b.base_z));
    m["yaw_deg"] = yaml_scalar(rad2deg(wrap_2pi(b.yaw)));
    m["size_m"] = yaml_flow_vector(Vec3(b.width_m, b.depth_m, b.height_m));
    m["storey_m"] = yaml_scalar(b.facade.storey_m);
    m["bay_m"] = yaml_scalar(b.facade.bay_m);
    m["wall_reflectance"] = yaml_scalar(b.facade.wall_reflectance);
    m["glass_reflectance"] = yaml_scalar(b.facade.glass_reflectance);
    n["buildings"].push_back(m);
  }
  for (std::size_t k = 0; k < bg.trees.size(); ++k) {
    const Tree& t = bg.trees[k];
    YAML::Node m;
    m["name"] = fmt::format("tree-{}", k + 1);
    m["base_m"] = yaml_flow_vector(t.base);
    m["height_m"] = yaml_scalar(t.height_m);
    m["crown_radius_m"] = yaml_scalar(t.crown_radius_m);
    m["crown_half_height_m"] = yaml_scalar(t.crown_half_height_m);
    m["reflectance"] = yaml_scalar(t.reflectance);
    m["blobs"] = t.blobs;
    n["trees"].push_back(m);
  }
  return n;
}

YAML::Node walk_node(const WalkDraw& w) {
  YAML::Node n;
  n["target_width_px"] = yaml_scalar(w.target_width_px);
  n["distance_m"] = yaml_scalar(w.distance_m);
  n["azimuth_magnetic_deg"] = yaml_scalar(rad2deg(w.azimuth));
  n["height_m"] = yaml_scalar(w.height_m);
  n["board_max_distance_m"] = yaml_scalar(w.board_max_m);
  n["holds_s"] = flow_list(w.holds_s);
  n["photo_instant_in_hold"] = flow_list(w.instants);
  n["walk_speed_m_s"] = yaml_scalar(w.walk_speed_m_s);
  n["max_turn_deg_s"] = yaml_scalar(w.max_turn_deg_s);
  n["gait_bob"]["amplitude_m"] = yaml_scalar(w.bob.amplitude_m);
  n["gait_bob"]["frequency_hz"] = yaml_scalar(w.bob.frequency_hz);
  n["tremor_deg_rms"] = yaml_scalar(w.tremor_deg);
  return n;
}

void add_antenna_keys(YAML::Node n, const SimAntenna& a, const RoiDraw& roi, double width_px) {
  n["panel"]["bracket_end_fraction"] = yaml_scalar(a.spec.bracket_end_fraction);
  n["panel"]["end_cap_thickness_m"] = yaml_scalar(a.finish.end_cap_thickness_m);
  n["panel"]["end_cap_height_m"] = yaml_scalar(a.finish.end_cap_height_m);
  YAML::Node f;
  f["look"] = to_string(a.finish.look);
  f["radome_albedo"] = yaml_scalar(a.finish.radome_albedo);
  f["cap_reflectance"] = yaml_scalar(a.finish.cap_reflectance);
  if (a.finish.look == RadomeLook::kRibbed) {
    f["rib_period_m"] = yaml_scalar(a.finish.rib_period_m);
    f["rib_contrast"] = yaml_scalar(a.finish.rib_contrast);
  }
  n["finish"] = f;
  YAML::Node m;
  m["pipe_xy_m"] = flow_list(std::array<double, 2>{a.mount_xy.x(), a.mount_xy.y()});
  m["pipe_radius_m"] = yaml_scalar(a.mount_radius_m);
  m["arm_m"] = yaml_scalar(a.arm_m);
  n["mount"] = m;
  n["roi_margin_fraction"] = flow_list(roi.margin_fraction);
  n["width_px"] = yaml_scalar(std::round(width_px * 10.0) / 10.0);
}

}  // namespace

void add_wide_site_truth(YAML::Node& root, const AntennaTruth& at) {
  if (!at.wide) throw std::invalid_argument("add_wide_site_truth: not a wide site");
  const SiteDraw& s = *at.wide;
  root["distribution"] = "wide";
  root["site_draw_attempt"] = s.attempt;  // draw_wide_site(seed, options, attempt) drew it
  root["photo"] = photo_node(s.photo);
  root["light"] = light_node(s.light);
  root["background"] = background_node(s.background);
  root["arrangement"] = to_string(at.layout.arrangement);
  for (const Strut& strut : at.layout.frame) {
    YAML::Node n;
    n["name"] = strut.name;
    n["a_m"] = yaml_flow_vector(strut.a);
    n["b_m"] = yaml_flow_vector(strut.b);
    n["radius_m"] = yaml_scalar(strut.radius_m);
    root["frame"].push_back(n);
  }
  root["metal_albedo"] = yaml_scalar(at.layout.metal_albedo);
  root["walk"] = walk_node(s.walk);
  for (std::size_t k = 0; k < at.layout.antennas.size(); ++k)
    add_antenna_keys(root["antennas"][k], at.layout.antennas[k], s.roi.at(k), at.width_px.at(k));
}

}  // namespace antpose::sim
