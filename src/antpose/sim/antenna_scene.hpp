// The 3-D scene of the antenna scenario (`antpose simulate capture --scenario antenna`): a
// steel mast with 1–3 panel antennas clamped to it by short arms, on a roof (with parapets and
// the street below) or on open ground, and a magnetised-steel disturbance near the mast.
//
// Antennas are the parametric panels of model/antenna_model.hpp (rounded vertical edges, two
// brackets on the back plate) placed by R_world_antenna = Rz(−az) Rx(−downtilt) Ry(roll)
// (notes/antenna-model.md) in the simulator's world (ENU with magnetic north). Each bracket is
// joined to the mast by a horizontal arm ending in a clamp around the pole; with downtilt the
// upper arm is longer, as with a real tilt kit.
//
// Magnetic disturbance: a magnetised steel mast is modelled as a line of equal point dipoles
// along its axis (induced magnetisation along the Earth field plus a horizontal remanent part),
// evaluated at the phone's position (ImuSimulation::dipoles), so the error changes along the
// walk. The moment is scaled so that magnetic north at the middle of the walk is turned by a
// drawn 3–8°.
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "antpose/model/antenna_model.hpp"
#include "antpose/sim/imu_simulator.hpp"
#include "antpose/sim/photo_simulator.hpp"

namespace antpose::sim {

enum class AntennaSetting { kRooftop, kGround };
enum class RadomeLook { kPlain, kWeathered };
std::string to_string(AntennaSetting setting);
std::string to_string(RadomeLook look);
/// "rooftop" | "ground"; InputError naming --setting otherwise.
AntennaSetting parse_antenna_setting(const std::string& name);
/// "plain" | "weathered"; InputError naming --radome otherwise.
RadomeLook parse_radome_look(const std::string& name);

/// A closed, outward-wound box centred at the origin with half sizes `half` (x, y, z), m.
model::Mesh box_mesh(const Vec3& half);
/// A closed, outward-wound cylinder from a to b (world or object frame), `segments` facets.
model::Mesh cylinder_mesh(const Vec3& a, const Vec3& b, double radius, int segments);

/// One simulated antenna (angles in radians, azimuth magnetic: the world's y is magnetic north).
struct SimAntenna {
  std::string name;        // antenna-1, antenna-2, ...
  std::string model_name;  // a model::builtin_panel name
  model::PanelSpec spec;   // the sizes of that built-in
  Mat3 R_world_antenna = Mat3::Identity();
  Vec3 p_world_antenna = Vec3::Zero();  // box centre, m
  double azimuth_magnetic = 0, downtilt = 0, roll = 0;
};

/// Mast and antennas: the mast is a vertical pole on the z axis from z = 0 (roof or ground) to
/// mast_top_m.
struct AntennaLayout {
  AntennaSetting setting = AntennaSetting::kRooftop;
  double mast_radius_m = 0.057, mast_top_m = 4.0;
  double building_height_m = 0.0;  // rooftop: the street is this far below the roof
  std::vector<SimAntenna> antennas;
};

/// Draws a layout: antenna 1's azimuth uniform in [0, 360), the others ~120° apart (±10°),
/// downtilt 0–12°, roll ±2°, models among the built-in panels; rooftop: centres 2.0–3.2 m
/// above the roof on a 114 mm pipe; ground: centres 10–20 m up a 0.5 m monopole.
AntennaLayout draw_antenna_layout(AntennaSetting setting, int antennas, std::mt19937_64& rng);

/// The meshes: mast, each panel (radome albedo 0.72; brackets, arms and clamps metal grey),
/// arms and clamps. Weathered radomes get weathering_reflectance.
std::vector<MeshObject> antenna_meshes(const AntennaLayout& layout, RadomeLook look, std::uint64_t seed);

/// The reflectance multiplier of a weathered radome at an antenna-frame point: low-contrast
/// dirt (±3 % on a 1–10 cm scale), vertical streaks, dirt towards the bottom, a maker's label
/// near the bottom of the radome and darker end caps; brackets (behind the back plate) 0.5.
/// Deterministic for a seed; thread-safe.
std::function<double(const Vec3&)> weathering_reflectance(const model::PanelSpec& spec, std::uint64_t seed);

/// Roof (membrane) with four parapets 1.1 m high at ±half_size_m and the street below, or open
/// ground (asphalt/gravel), as textured patches.
std::vector<TexturedPatch> antenna_site_patches(const AntennaLayout& layout, double half_size_m, std::uint64_t seed);

/// The dipole line of a magnetised mast (see the file comment) scaled so that the horizontal
/// field at `p_reference` turns by `north_shift_rad` (sign included); `field_world_uT` is the
/// undisturbed Earth field. std::runtime_error if no moment direction turns it.
std::vector<MagneticDipole> mast_dipoles(const AntennaLayout& layout, const Vec3& field_world_uT,
                                         const Vec3& p_reference, double north_shift_rad, std::mt19937_64& rng);

/// Clockwise rotation (rad) of the horizontal magnetic field at p_world caused by the dipoles:
/// a heading from the magnetometer there is too small by this angle.
double north_shift(const std::vector<MagneticDipole>& dipoles, const Vec3& field_world_uT, const Vec3& p_world);

}  // namespace antpose::sim
