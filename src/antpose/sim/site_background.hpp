// What stands behind the mast of a wide antenna site: open sky, neighbouring buildings (boxes
// with window-grid facades) or trees (blobby crowns on trunks). The measurement must find a
// panel's outline against them, as against the sky.
//
// Objects stand behind the mast as seen from the walk (their azimuth from the mast within ±70°
// of the direction away from the walk), never between the phone and the antennas (the
// planning's occlusion check confirms it per photo). Half of them stand right behind the
// antennas (within ±15°), as tall as it takes (within their range) to rise above the line of
// sight from the middle of the walk over the antennas, so that the antennas are seen against
// them in many photos. On a rooftop they stand in the street below: buildings rise above the
// roof; a tree is kept only where its crown shows above the parapet from the middle of the walk.
#pragma once

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "antpose/sim/antenna_scene.hpp"
#include "antpose/sim/photo_simulator.hpp"

namespace antpose::sim {

enum class BackgroundKind { kSky, kBuildings, kTrees };
std::string to_string(BackgroundKind kind);
/// "sky" | "buildings" | "trees"; InputError naming --background otherwise.
BackgroundKind parse_background_kind(const std::string& name);

/// The facade of a building: storeys of bays, one window per bay.
struct Facade {
  double storey_m = 3.2, bay_m = 2.5;                           // window grid pitch
  double window_width_fraction = 0.5, window_height_fraction = 0.5;  // of the bay and storey
  double wall_reflectance = 0.5, glass_reflectance = 0.2;
  std::uint64_t seed = 0;  // noise of the wall and of each window (blinds, lights, reflections)
};

/// A box building standing on z = base_z.
struct Building {
  Vec2 centre_xy = Vec2::Zero();
  double base_z = 0.0, yaw = 0.0;  // yaw: rotation about z of the box's x axis from east, rad
  double width_m = 20.0, depth_m = 15.0, height_m = 20.0;
  Facade facade;
};

/// A tree: a trunk and a crown of one to three overlapping blobs (noisy ellipsoids).
struct Tree {
  Vec3 base = Vec3::Zero();  // foot of the trunk
  double height_m = 10.0, crown_radius_m = 3.0, crown_half_height_m = 3.5, trunk_radius_m = 0.2;
  double reflectance = 0.25;  // mean of the crown's noisy reflectance
  int blobs = 1;
  std::uint64_t seed = 0;
};

struct Background {
  BackgroundKind kind = BackgroundKind::kSky;
  std::vector<Building> buildings;
  std::vector<Tree> trees;
};

/// Where the background goes: the site and the middle of the walk.
struct BackgroundSite {
  AntennaSetting setting = AntennaSetting::kRooftop;
  double building_height_m = 0.0;  // rooftop: the street is this far below the roof
  double roof_half_m = 0.0;        // rooftop: the parapets at ±roof_half_m around the mast
  Vec3 walk_centre = Vec3::Zero();      // middle of the walk (camera height), world
  Vec3 antennas_centre = Vec3::Zero();  // mean of the antennas' centres, world
};

/// Draws the objects: buildings (2–6) 25–150 m from the mast (clear of the roof, the mast and
/// the walk), 10–60 m tall from the street, 10–40 m wide, 10–30 m deep, facing the mast ±30°;
/// trees (3–10) 10–40 m from the mast on the ground (rooftop: in the street, up to 60 m away,
/// only those whose crown shows), 6–20 m tall, reflectance 0.15–0.35. Sky: none.
Background draw_background(BackgroundKind kind, const BackgroundSite& site, std::mt19937_64& rng);

/// The buildings as textured patches (four facades and a flat roof each, named
/// building-<k>-<face>), facade textures seeded by their Facade::seed.
std::vector<TexturedPatch> background_patches(const Background& background);
/// The trees as meshes (one object per tree, tree-<k>: trunk and crown).
std::vector<MeshObject> background_meshes(const Background& background);

/// An icosphere (a subdivided icosahedron, 20·4^subdivisions faces) of unit radius: the
/// low-poly sphere of the tree crowns.
model::Mesh icosphere(int subdivisions);

}  // namespace antpose::sim
