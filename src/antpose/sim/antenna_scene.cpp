#include "antpose/sim/antenna_scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "antpose/sim/board_texture.hpp"
#include "antpose/sim/procedural_noise.hpp"
#include "antpose/sim/random.hpp"

namespace antpose::sim {

namespace {

Mat3 rot_antenna(double azimuth, double downtilt, double roll) {
  return rot_z(-azimuth) * rot_x(-downtilt) * rot_y(roll);
}

constexpr double kRadomeAlbedo = 0.72, kSteelAlbedo = 0.42;

}  // namespace

std::string to_string(AntennaSetting s) { return s == AntennaSetting::kRooftop ? "rooftop" : "ground"; }
std::string to_string(RadomeLook l) {
  switch (l) {
    case RadomeLook::kPlain:
      return "plain";
    case RadomeLook::kWeathered:
      return "weathered";
    case RadomeLook::kRibbed:
      return "ribbed";
  }
  return "unknown";
}
std::string to_string(Arrangement a) { return a == Arrangement::kSectors ? "sectors" : "side-by-side"; }

AntennaSetting parse_antenna_setting(const std::string& name) {
  if (name == "rooftop") return AntennaSetting::kRooftop;
  if (name == "ground") return AntennaSetting::kGround;
  throw InputError("--setting", fmt::format("'{}' is not rooftop or ground", name));
}

RadomeLook parse_radome_look(const std::string& name) {
  for (const auto l : {RadomeLook::kPlain, RadomeLook::kWeathered, RadomeLook::kRibbed})
    if (to_string(l) == name) return l;
  throw InputError("--radome", fmt::format("'{}' is not plain, weathered or ribbed", name));
}

Arrangement parse_arrangement(const std::string& name) {
  for (const auto a : {Arrangement::kSectors, Arrangement::kSideBySide})
    if (to_string(a) == name) return a;
  throw InputError("--arrangement", fmt::format("'{}' is not sectors or side-by-side", name));
}

Vec3 heading(double azimuth) { return {std::sin(azimuth), std::cos(azimuth), 0.0}; }

model::Mesh box_mesh(const Vec3& h) {
  model::Mesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1 ? 1 : -1) * h.x(), (i & 2 ? 1 : -1) * h.y(), (i & 4 ? 1 : -1) * h.z());
  // Faces counter-clockwise seen from outside.
  const std::array<std::array<std::uint32_t, 4>, 6> faces{
      {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}}};
  for (const auto& f : faces) {
    m.triangles.push_back({f[0], f[1], f[2]});
    m.triangles.push_back({f[0], f[2], f[3]});
  }
  return m;
}

model::Mesh cylinder_mesh(const Vec3& a, const Vec3& b, double radius, int segments) {
  if (segments < 3 || !(radius > 0.0) || !((b - a).norm() > 0.0))
    throw std::invalid_argument("cylinder_mesh: bad size");
  const Vec3 axis = (b - a).normalized();
  const Vec3 u = (std::abs(axis.z()) < 0.9 ? axis.cross(Vec3::UnitZ()) : axis.cross(Vec3::UnitX())).normalized();
  const Vec3 v = axis.cross(u);
  model::Mesh m;
  const auto n = static_cast<std::uint32_t>(segments);
  for (std::uint32_t i = 0; i < n; ++i) {
    const double t = 2.0 * std::numbers::pi * i / n;
    const Vec3 r = radius * (std::cos(t) * u + std::sin(t) * v);
    m.vertices.push_back(a + r);
    m.vertices.push_back(b + r);
  }
  const auto ca = static_cast<std::uint32_t>(m.vertices.size());
  m.vertices.push_back(a);
  m.vertices.push_back(b);
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::uint32_t j = (i + 1) % n;
    // (u, v, axis) is right-handed: counter-clockwise about the axis is the outward winding.
    m.triangles.push_back({2 * i, 2 * j, 2 * j + 1});
    m.triangles.push_back({2 * i, 2 * j + 1, 2 * i + 1});
    m.triangles.push_back({ca, 2 * j, 2 * i});
    m.triangles.push_back({ca + 1, 2 * i + 1, 2 * j + 1});
  }
  return m;
}

AntennaLayout draw_antenna_layout(AntennaSetting setting, int antennas, std::mt19937_64& rng) {
  if (antennas < 1 || antennas > 3) throw InputError("--antennas", fmt::format("{} is outside 1..3", antennas));
  AntennaLayout L;
  L.setting = setting;
  const bool roof = setting == AntennaSetting::kRooftop;
  L.mast_radius_m = roof ? 0.057 : 0.25;  // a 114 mm pipe; a 0.5 m monopole
  L.building_height_m = roof ? uniform(rng, 15.0, 30.0) : 0.0;
  const double z_centre = roof ? uniform(rng, 2.0, 3.2) : uniform(rng, 10.0, 20.0);
  const double az0 = uniform(rng, 0.0, 2.0 * std::numbers::pi);
  const auto names = model::builtin_panel_names();
  double top = 0.0;
  for (int k = 0; k < antennas; ++k) {
    SimAntenna a;
    a.name = fmt::format("antenna-{}", k + 1);
    a.model_name =
        names[static_cast<std::size_t>(std::uniform_int_distribution<int>(0, static_cast<int>(names.size()) - 1)(rng))];
    const model::AntennaModel m = model::builtin_panel(a.model_name);
    a.spec.width_m = m.size_m.x(), a.spec.depth_m = m.size_m.y(), a.spec.height_m = m.size_m.z();
    const double jitter = k == 0 ? 0.0 : deg2rad(uniform(rng, -10.0, 10.0));
    a.azimuth_magnetic =
        std::fmod(az0 + k * 2.0 * std::numbers::pi / 3.0 + jitter + 2.0 * std::numbers::pi, 2.0 * std::numbers::pi);
    a.downtilt = deg2rad(uniform(rng, 0.0, 12.0));
    a.roll = deg2rad(uniform(rng, -2.0, 2.0));
    a.R_world_antenna = rot_antenna(a.azimuth_magnetic, a.downtilt, a.roll);
    // The nearer bracket's arm 12 cm long beyond the pole's surface.
    a.mount_radius_m = L.mast_radius_m;
    a.arm_m = 0.12;
    a.p_world_antenna = centre_on_mount(a, Vec2::Zero(), a.mount_radius_m, a.arm_m, z_centre + uniform(rng, -0.05, 0.05));
    top = std::max(top, a.p_world_antenna.z() + a.spec.height_m / 2);
    L.antennas.push_back(a);
  }
  L.mast_top_m = top + (roof ? 0.3 : 1.0);
  return L;
}

std::function<double(const Vec3&)> weathering_reflectance(const model::PanelSpec& s, std::uint64_t seed) {
  // The label: lines of "text" (dark bars of random lengths) on white, near the bottom of the
  // radome's flat front.
  const double half_w = std::min(0.06, (s.width_m / 2 - s.edge_radius_m) - 0.005);
  const double z0 = -s.height_m / 2 + 0.10, z1 = z0 + 0.08;
  std::mt19937_64 rng(mix_bits(seed ^ 0x1abe1ULL));
  std::vector<std::array<double, 4>> bars;  // x0, x1, z0, z1 in the antenna frame
  for (int line = 0; line < 4; ++line) {
    const double zb = z1 - 0.012 - line * 0.017, zt = zb + (line == 0 ? 0.010 : 0.007);
    double x = -half_w + 0.008;
    while (x < half_w - 0.012) {
      const double len = uniform(rng, 0.004, line == 0 ? 0.03 : 0.015);
      const double x_end = std::min(x + len, half_w - 0.008);
      bars.push_back({x, x_end, zb, zt});
      x = x_end + uniform(rng, 0.002, 0.006);
    }
  }
  const double front = s.depth_m / 2 - 1e-4, back = -s.depth_m / 2 - 1e-4, cap = s.height_m / 2 - 1e-4;
  const std::uint64_t s1 = mix_bits(seed + 1), s2 = mix_bits(seed + 2), s3 = mix_bits(seed + 3);
  return [=](const Vec3& p) {
    if (p.y() < back) return 0.5;           // bracket: galvanised steel
    if (std::abs(p.z()) > cap) return 0.8;  // end caps: a darker grey plastic
    if (p.y() > front && std::abs(p.x()) <= half_w && p.z() >= z0 && p.z() <= z1) {
      for (const auto& b : bars)
        if (p.x() >= b[0] && p.x() <= b[1] && p.z() >= b[2] && p.z() <= b[3]) return 0.2;
      return 1.25;  // label paper
    }
    // Dirt: ±3 % over 1–10 cm; streaks: stretched 30× along the panel; grime towards the bottom.
    const double dirt =
        0.6 * value_noise(p / 0.08, s1) + 0.3 * value_noise(p / 0.025, s2) + 0.1 * value_noise(p / 0.01, s2 + 7);
    const double streak = value_noise(Vec3(p.x() / 0.012, p.y() / 0.012, p.z() / 0.4), s3);
    const double grime = std::exp(-(p.z() + s.height_m / 2) / 0.15);
    return std::clamp(1.0 + 0.03 * dirt - 0.025 * std::max(0.0, streak) - 0.05 * grime, 0.5, 1.2);
  };
}

std::array<Vec3, 2> bracket_back_points(const model::PanelSpec& s) {
  const double kz = 0.5 - s.bracket_end_fraction;
  return {Vec3(0.0, -s.depth_m / 2 - s.bracket_depth_m, -kz * s.height_m),
          Vec3(0.0, -s.depth_m / 2 - s.bracket_depth_m, kz * s.height_m)};
}

Vec3 centre_on_mount(const SimAntenna& a, const Vec2& mount_xy, double mount_radius_m, double arm_m, double z_m) {
  const Vec3 b_h(std::sin(a.azimuth_magnetic), std::cos(a.azimuth_magnetic), 0.0);
  double s_min = 0.0;
  for (const Vec3& bracket : bracket_back_points(a.spec)) {
    const Vec3 q = a.R_world_antenna * bracket;
    s_min = std::min(s_min, q.dot(b_h));
  }
  const double r_c = mount_radius_m + arm_m - s_min;
  return r_c * b_h + Vec3(mount_xy.x(), mount_xy.y(), z_m);
}

std::array<Arm, 2> antenna_arms(const SimAntenna& a) {
  std::array<Arm, 2> out;
  const auto brackets = bracket_back_points(a.spec);
  for (std::size_t k = 0; k < 2; ++k) {
    const Vec3 q = a.p_world_antenna + a.R_world_antenna * brackets[k];
    Arm& arm = out[k];
    arm.name = fmt::format("{}-arm-{}", a.name, k == 0 ? "low" : "high");
    arm.axis_point = Vec3(a.mount_xy.x(), a.mount_xy.y(), q.z());
    const Vec3 along = q - arm.axis_point;
    arm.length_m = along.norm();
    arm.R_world_arm.col(0) = along / arm.length_m;
    arm.R_world_arm.col(2) = Vec3::UnitZ();
    arm.R_world_arm.col(1) = arm.R_world_arm.col(2).cross(arm.R_world_arm.col(0));
    arm.centre = arm.axis_point + along / 2;
  }
  return out;
}

namespace {

constexpr double kCrease = deg2rad(40.0);

// The panel's parts in the antenna frame: its parametric panel, then the end caps (a separate
// moulding, so rendered as parts of their own).
std::vector<model::Mesh> rendered_panel_parts(const SimAntenna& a) {
  std::vector<model::Mesh> parts{model::parametric_panel(a.spec).mesh_antenna};
  model::PanelSpec capped = a.spec;
  capped.end_cap_height_m = a.finish.end_cap_height_m, capped.end_cap_rim_m = a.finish.end_cap_thickness_m;
  for (auto& cap : model::end_cap_meshes(capped)) parts.push_back(std::move(cap));
  return parts;
}

// Arm and clamp objects (lower pair first), as the classic scenes have always drawn them.
std::vector<MeshObject> arm_objects(const SimAntenna& a, double arm_albedo, double clamp_albedo) {
  std::vector<MeshObject> out;
  for (const Arm& arm : antenna_arms(a)) {
    MeshObject box;
    box.name = arm.name;
    box.mesh = box_mesh(Vec3(arm.length_m / 2, 0.025, 0.025));
    box.R_world_object = arm.R_world_arm;
    box.p_world_object = arm.centre;
    box.albedo = arm_albedo;
    out.push_back(box);
    MeshObject clamp;
    clamp.name = fmt::format("{}-clamp-{}", a.name, arm.name.substr(arm.name.rfind('-') + 1));
    const double c = a.mount_radius_m + 0.015;
    clamp.mesh = box_mesh(Vec3(c, c, 0.05));
    clamp.R_world_object = arm.R_world_arm;
    clamp.p_world_object = arm.axis_point;
    clamp.albedo = clamp_albedo;
    out.push_back(clamp);
  }
  return out;
}

MeshObject mast_object(const AntennaLayout& L, double albedo) {
  MeshObject mast;
  mast.name = "mast";
  mast.mesh = cylinder_mesh(Vec3::Zero(), Vec3(0.0, 0.0, L.mast_top_m), L.mast_radius_m, 24);
  mast.corner_normals = smooth_corner_normals(mast.mesh, kCrease);
  mast.albedo = albedo;
  return mast;
}

// A finished panel's reflectance: end caps, then the brackets (at the steel's own albedo), then
// the radome's look.
std::function<double(const Vec3&)> finish_reflectance(const SimAntenna& a, double metal_albedo, std::uint64_t seed) {
  const model::PanelSpec& s = a.spec;
  const PanelFinish& f = a.finish;
  std::function<double(const Vec3&)> look = [](const Vec3&) { return 1.0; };
  if (f.look == RadomeLook::kWeathered) look = weathering_reflectance(s, seed);
  if (f.look == RadomeLook::kRibbed) look = ribbed_reflectance(s, f.rib_period_m, f.rib_contrast);
  const double cap_from = s.height_m / 2 - std::max(f.end_cap_height_m, 1e-4), back = -s.depth_m / 2 - 1e-4;
  const double bracket = metal_albedo / f.radome_albedo, cap = f.cap_reflectance;
  return [=](const Vec3& p) {
    if (std::abs(p.z()) > cap_from) return cap;
    if (p.y() < back) return bracket;
    return look(p);
  };
}

}  // namespace

model::Mesh rendered_panel_mesh(const SimAntenna& a) {
  auto parts = rendered_panel_parts(a);
  model::Mesh mesh = std::move(parts.front());
  for (std::size_t i = 1; i < parts.size(); ++i) model::append_mesh(mesh, parts[i]);
  return mesh;
}

std::function<double(const Vec3&)> ribbed_reflectance(const model::PanelSpec& s, double period_m, double contrast) {
  if (!(period_m > 0.0) || !(contrast >= 0.0 && contrast < 1.0))
    throw std::invalid_argument(fmt::format("ribbed_reflectance: period {} m must be > 0, contrast {} in [0, 1)",
                                            period_m, contrast));
  const double front = s.depth_m / 2 - 1e-4;
  return [=](const Vec3& p) {
    if (p.y() < front) return 1.0;
    const double g = 0.5 * (1.0 + std::cos(2.0 * std::numbers::pi * p.x() / period_m));
    return 1.0 + contrast * (0.375 - g * g);
  };
}

std::vector<MeshObject> antenna_meshes(const AntennaLayout& L, RadomeLook look, std::uint64_t seed) {
  if (look == RadomeLook::kRibbed) throw std::invalid_argument("antenna_meshes: ribbed radomes are finished panels");
  std::vector<MeshObject> out{mast_object(L, kSteelAlbedo)};
  for (std::size_t k = 0; k < L.antennas.size(); ++k) {
    const SimAntenna& a = L.antennas[k];
    MeshObject panel;
    panel.name = a.name;
    panel.mesh = rendered_panel_mesh(a);
    panel.corner_normals = smooth_corner_normals(panel.mesh, kCrease);
    panel.R_world_object = a.R_world_antenna;
    panel.p_world_object = a.p_world_antenna;
    panel.albedo = kRadomeAlbedo;
    if (look == RadomeLook::kWeathered) {
      panel.reflectance = weathering_reflectance(a.spec, seed * 31 + k);
    } else {
      const double back = -a.spec.depth_m / 2 - 1e-4;
      panel.reflectance = [back](const Vec3& p) { return p.y() < back ? 0.5 : 1.0; };  // uniform radome
    }
    out.push_back(panel);
    const auto arms = arm_objects(a, kSteelAlbedo * 0.9, kSteelAlbedo * 0.8);
    out.insert(out.end(), arms.begin(), arms.end());
  }
  return out;
}

std::vector<MeshObject> finished_antenna_meshes(const AntennaLayout& L, std::uint64_t seed) {
  const double metal = L.metal_albedo;
  std::vector<MeshObject> out{mast_object(L, metal)};
  for (std::size_t k = 0; k < L.antennas.size(); ++k) {
    const SimAntenna& a = L.antennas[k];
    MeshObject panel;
    panel.name = a.name;
    for (const auto& part : rendered_panel_parts(a)) append_part(panel, part, kCrease);
    panel.R_world_object = a.R_world_antenna;
    panel.p_world_object = a.p_world_antenna;
    panel.albedo = a.finish.radome_albedo;
    panel.reflectance = finish_reflectance(a, metal, seed * 31 + k);
    out.push_back(panel);
    const auto arms = arm_objects(a, metal, 0.85 * metal);
    out.insert(out.end(), arms.begin(), arms.end());
  }
  for (const Strut& s : L.frame) {
    MeshObject strut;
    strut.name = s.name;
    strut.mesh = cylinder_mesh(s.a, s.b, s.radius_m, 16);
    strut.corner_normals = smooth_corner_normals(strut.mesh, kCrease);
    strut.albedo = metal;
    out.push_back(strut);
  }
  return out;
}

std::vector<TexturedPatch> antenna_site_patches(const AntennaLayout& L, double half_size_m, std::uint64_t seed) {
  std::vector<TexturedPatch> out;
  auto ground = [&](const std::string& name, double z, double half, std::shared_ptr<const Texture> tex) {
    TexturedPatch g;
    g.name = name;
    g.p_world_patch = Vec3(0.0, 0.0, z);
    g.min_xy = Eigen::Vector2d(-half, -half);
    g.max_xy = Eigen::Vector2d(half, half);
    g.texture = std::move(tex);
    return g;
  };
  if (L.setting == AntennaSetting::kRooftop) {
    // Roof membrane and parapets (the room of room_patches, 1.1 m walls), the street below.
    out = room_patches(seed, half_size_m, 1.1);
    out[0].name = "roof";
    out[0].texture = procedural_texture(seed * 7 + 11, 3.0, 1024, 0.42, 0.08);
    for (std::size_t i = 1; i < out.size(); ++i)
      out[i].name = "parapet" + out[i].name.substr(4);  // "wall-north" → "parapet-north"
    out.push_back(
        ground("street", -L.building_height_m, 150.0, procedural_texture(seed * 7 + 12, 4.0, 1024, 0.25, 0.08)));
  } else {
    out.push_back(ground("ground", 0.0, 150.0, procedural_texture(seed * 7 + 13, 2.0, 1024, 0.32, 0.09)));
  }
  return out;
}

double north_shift(const std::vector<MagneticDipole>& dipoles, const Vec3& field_world_uT, const Vec3& p_world) {
  Vec3 B = field_world_uT;
  for (const auto& d : dipoles) B += dipole_field_uT(d, p_world);
  return std::atan2(B.x(), B.y()) - std::atan2(field_world_uT.x(), field_world_uT.y());
}

std::vector<MagneticDipole> mast_dipoles(const AntennaLayout& L, const Vec3& field_world_uT, const Vec3& p_reference,
                                         double shift, std::mt19937_64& rng) {
  constexpr int kCount = 12;
  const Eigen::Vector2d h0(field_world_uT.x(), field_world_uT.y());
  // Magnetic north turned clockwise by `shift`.
  const Eigen::Vector2d u(std::cos(shift) * h0.x() + std::sin(shift) * h0.y(),
                          -std::sin(shift) * h0.x() + std::cos(shift) * h0.y());
  auto cross2 = [](const Eigen::Vector2d& a, const Eigen::Vector2d& b) { return a.x() * b.y() - a.y() * b.x(); };
  std::vector<MagneticDipole> best;
  double best_scale = std::numeric_limits<double>::infinity();
  for (int attempt = 0; attempt < 32; ++attempt) {
    // Induced (along the Earth field) plus a horizontal remanent part of random direction.
    const double psi = uniform(rng, 0.0, 2.0 * std::numbers::pi), remanent = uniform(rng, 0.3, 1.0);
    const Vec3 dir = (field_world_uT.normalized() + remanent * Vec3(std::cos(psi), std::sin(psi), 0.0)).normalized();
    std::vector<MagneticDipole> unit(kCount);
    Vec3 d1 = Vec3::Zero();
    for (int i = 0; i < kCount; ++i) {
      unit[static_cast<std::size_t>(i)].p_world = Vec3(0.0, 0.0, L.mast_top_m * (i + 0.5) / kCount);
      unit[static_cast<std::size_t>(i)].moment_Am2 = dir;
      d1 += dipole_field_uT(unit[static_cast<std::size_t>(i)], p_reference);
    }
    // Scale s with (h0 + s d1_h) parallel to u, pointing the same way.
    const Eigen::Vector2d d1h(d1.x(), d1.y());
    const double den = cross2(u, d1h);
    if (std::abs(den) < 1e-12) continue;
    const double s = -cross2(u, h0) / den;
    if ((h0 + s * d1h).dot(u) <= 0.0) continue;
    if (std::abs(s) < best_scale) {
      best_scale = std::abs(s);
      for (auto& d : unit) d.moment_Am2 *= s;
      best = unit;
    }
  }
  if (best.empty()) throw std::runtime_error("mast_dipoles: no dipole direction turns the field at the walk");
  return best;
}

}  // namespace antpose::sim
