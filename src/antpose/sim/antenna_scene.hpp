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
// Wide sites (antenna_site.hpp) hang the panels on their own arms (sectors) or side by side on a
// frame of pipes (antenna_mounts.hpp), and render each panel with its own finish: the shape of
// the hardware (edge radius, brackets, end caps standing out of the radome), not the datasheet
// box the measurement is given, and the radome's colour and look.
//
// Magnetic disturbance: a magnetised steel mast is modelled as a line of equal point dipoles
// along its axis (induced magnetisation along the Earth field plus a horizontal remanent part),
// evaluated at the phone's position (ImuSimulation::dipoles), so the error changes along the
// walk. The moment is scaled so that magnetic north at the middle of the walk is turned by a
// drawn 3–8°.
#pragma once

#include <array>
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
enum class RadomeLook { kPlain, kWeathered, kRibbed };
enum class Arrangement { kSectors, kSideBySide };
std::string to_string(AntennaSetting setting);
std::string to_string(RadomeLook look);
std::string to_string(Arrangement arrangement);
/// "rooftop" | "ground"; InputError naming --setting otherwise.
AntennaSetting parse_antenna_setting(const std::string& name);
/// "plain" | "weathered" | "ribbed"; InputError naming --radome otherwise.
RadomeLook parse_radome_look(const std::string& name);
/// "sectors" | "side-by-side"; InputError naming --arrangement otherwise.
Arrangement parse_arrangement(const std::string& name);

/// The horizontal unit vector at an azimuth (rad, clockwise from the world's y: magnetic north).
Vec3 heading(double azimuth);

/// A closed, outward-wound box centred at the origin with half sizes `half` (x, y, z), m.
model::Mesh box_mesh(const Vec3& half);
/// A closed, outward-wound cylinder from a to b (world or object frame), `segments` facets.
model::Mesh cylinder_mesh(const Vec3& a, const Vec3& b, double radius, int segments);

/// How a rendered panel looks beyond its shape. The defaults are those of the classic scenes;
/// wide sites draw every field (antenna_site.hpp).
struct PanelFinish {
  RadomeLook look = RadomeLook::kWeathered;
  double radome_albedo = 0.72;
  double cap_reflectance = 0.8;                   // end caps, relative to the radome
  double rib_period_m = 0.0, rib_contrast = 0.0;  // ribbed: period across the width, peak-to-peak contrast
  /// End caps standing out of the radome all round by this much (a separate moulding on real
  /// panels), end_cap_height_m long; height 0: no separate caps.
  double end_cap_thickness_m = 0.0, end_cap_height_m = 0.0;
};

/// One simulated antenna (angles in radians, azimuth magnetic: the world's y is magnetic north).
struct SimAntenna {
  std::string name;        // antenna-1, antenna-2, ...
  std::string model_name;  // a model::builtin_panel name: the datasheet box the user measures with
  model::PanelSpec spec;   // the rendered panel (classic: that built-in's own)
  PanelFinish finish;      // how it is rendered (finished_antenna_meshes; classic scenes ignore it)
  Mat3 R_world_antenna = Mat3::Identity();
  Vec3 p_world_antenna = Vec3::Zero();  // box centre, m
  double azimuth_magnetic = 0, downtilt = 0, roll = 0;
  /// The vertical pipe its arms are clamped to: the mast (axis at the origin) or a frame pipe.
  Vec2 mount_xy = Vec2::Zero();
  double mount_radius_m = 0.057;
  double arm_m = 0.12;  // the nearer bracket's arm beyond the pipe's surface
};

/// A straight tube of the mounting hardware (a frame's bars, pipes and stand-offs), world frame.
struct Strut {
  std::string name;
  Vec3 a = Vec3::Zero(), b = Vec3::Zero();
  double radius_m = 0.03;
};

/// Mast and antennas: the mast is a vertical pole on the z axis from z = 0 (roof or ground) to
/// mast_top_m.
struct AntennaLayout {
  AntennaSetting setting = AntennaSetting::kRooftop;
  double mast_radius_m = 0.057, mast_top_m = 4.0;
  double building_height_m = 0.0;  // rooftop: the street is this far below the roof
  std::vector<SimAntenna> antennas;
  Arrangement arrangement = Arrangement::kSectors;
  std::vector<Strut> frame;    // side-by-side: the frame's bars, pipes and stand-offs
  double metal_albedo = 0.42;  // finished meshes: the galvanised steel of mast, arms, clamps and frame
};

/// Where the arms meet a panel: the centres of its two brackets' back faces, antenna frame
/// (lower, upper).
std::array<Vec3, 2> bracket_back_points(const model::PanelSpec& spec);

/// The centre of a panel (spec and R_world_antenna set) whose brackets are joined by horizontal
/// arms to a vertical pipe at `mount_xy` of radius `mount_radius_m`: out from the pipe along the
/// horizontal boresight so that the nearer bracket's arm is `arm_m` long beyond the pipe's
/// surface, at height z_m.
Vec3 centre_on_mount(const SimAntenna& antenna, const Vec2& mount_xy, double mount_radius_m, double arm_m,
                     double z_m);

/// A horizontal arm from a panel's mount axis to one of its brackets: a 5 × 5 cm box of
/// `length_m` whose x axis runs from the axis to the bracket, centred at `centre`.
struct Arm {
  std::string name;  // <antenna>-arm-low | <antenna>-arm-high
  Mat3 R_world_arm = Mat3::Identity();
  Vec3 centre = Vec3::Zero(), axis_point = Vec3::Zero();  // axis_point: on the mount axis
  double length_m = 0.0;
};
/// The two arms of an antenna (lower first); with downtilt the upper arm is longer.
std::array<Arm, 2> antenna_arms(const SimAntenna& antenna);

/// The rendered panel in the antenna frame: its parametric panel with the end caps (if any).
model::Mesh rendered_panel_mesh(const SimAntenna& antenna);

/// Draws a layout: antenna 1's azimuth uniform in [0, 360), the others ~120° apart (±10°),
/// downtilt 0–12°, roll ±2°, models among the built-in panels; rooftop: centres 2.0–3.2 m
/// above the roof on a 114 mm pipe; ground: centres 10–20 m up a 0.5 m monopole.
AntennaLayout draw_antenna_layout(AntennaSetting setting, int antennas, std::mt19937_64& rng);

/// The meshes of a classic scene: mast, each panel (radome albedo 0.72; brackets, arms and
/// clamps metal grey), arms and clamps. Weathered radomes get weathering_reflectance; ribbed is
/// for finished panels only (std::invalid_argument).
std::vector<MeshObject> antenna_meshes(const AntennaLayout& layout, RadomeLook look, std::uint64_t seed);

/// The meshes of a wide site: mast, each panel with its own finish (end caps part of the panel's
/// object), its arms and clamps, and the frame's struts; all steel at the layout's metal albedo
/// (clamps 15 % darker). Mesh names as antenna_meshes, plus the struts' names.
std::vector<MeshObject> finished_antenna_meshes(const AntennaLayout& layout, std::uint64_t seed);

/// The reflectance multiplier of a ribbed radome's front: vertical grooves across the width,
/// 1 + contrast (3/8 − g(x)) with the groove profile g = ((1 + cos(2π x / period)) / 2)² (mean
/// 3/8, so the mean stays 1 and the peak-to-peak modulation is `contrast`), grooves aligned to the
/// panel's centre line; 1 elsewhere on the radome.
std::function<double(const Vec3&)> ribbed_reflectance(const model::PanelSpec& spec, double period_m, double contrast);

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
