#include "antpose/sim/site_background.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "antpose/core/error.hpp"
#include "antpose/sim/board_texture.hpp"
#include "antpose/sim/procedural_noise.hpp"
#include "antpose/sim/random.hpp"

namespace antpose::sim {

namespace {

// Azimuth from the mast around the direction away from the walk: of every object, and of those
// right behind the antennas.
constexpr double kSpread = deg2rad(70.0), kBehind = deg2rad(15.0);

double azimuth_of(const Vec3& v) { return std::atan2(v.x(), v.y()); }

// A facade texture: one repeating tile of 4 storeys, its bays fitted to the tile, windows painted
// over band-limited wall noise; each window's glass varies (blinds, lights, reflections).
std::shared_ptr<const Texture> facade_texture(const Facade& f, double* tile_m) {
  constexpr int kTexels = 512;
  *tile_m = 4.0 * f.storey_m;
  const int bays = std::max(1, static_cast<int>(std::lround(*tile_m / f.bay_m)));
  const auto wall = procedural_texture(f.seed, *tile_m, kTexels, f.wall_reflectance, 0.04);
  cv::Mat img = wall->levels.front().clone();
  const double ppm = kTexels / *tile_m, bay = *tile_m / bays;
  for (int i = 0; i < bays; ++i)
    for (int j = 0; j < 4; ++j) {
      const double u = 0.5 * (lattice_value(i, j, 0, f.seed) + 1.0);  // [0, 1)
      const double glass = std::clamp(f.glass_reflectance * (0.6 + u), 0.02, 0.9);
      const double x0 = (i + 0.5 * (1.0 - f.window_width_fraction)) * bay;
      const double y0 = (j + 0.5 * (1.0 - f.window_height_fraction)) * f.storey_m;
      const cv::Rect r(static_cast<int>(std::lround(x0 * ppm)), static_cast<int>(std::lround(y0 * ppm)),
                       static_cast<int>(std::lround(f.window_width_fraction * bay * ppm)),
                       static_cast<int>(std::lround(f.window_height_fraction * f.storey_m * ppm)));
      img(r & cv::Rect(0, 0, kTexels, kTexels)).setTo(glass);
    }
  return std::make_shared<const Texture>(Texture::from_image(img, wall->texel_from_patch, true));
}

// An object's azimuth from the mast: right behind the antennas on half of the draws.
double draw_azimuth(double away, std::mt19937_64& rng, bool* behind) {
  *behind = uniform(rng, 0.0, 1.0) < 0.5;
  const double spread = *behind ? kBehind : kSpread;
  return away + uniform(rng, -spread, spread);
}

// The height (above the world's z = 0) of the line of sight from the middle of the walk over the
// antennas' centre, at the horizontal point p.
double sight_line_z(const BackgroundSite& site, const Vec2& p) {
  const Vec2 eye = site.walk_centre.head<2>(), antennas = site.antennas_centre.head<2>();
  const double rise = site.antennas_centre.z() - site.walk_centre.z();
  return site.walk_centre.z() + rise * (p - eye).norm() / std::max((antennas - eye).norm(), 1.0);
}

// A height uniform in [lo, hi], or, for an object right behind the antennas, at least `needed`
// (while that is within the range).
double draw_height(double lo, double hi, bool behind, double needed, std::mt19937_64& rng) {
  return uniform(rng, behind && needed <= hi ? std::max(lo, needed) : lo, hi);
}

// The world point of a tree's crown top and whether it shows above the parapet from `eye`: the
// sight line from the eye over the roof's edge (at height 1.1 m, where the line towards the tree
// leaves the roof square) must pass below the crown's top by a third of the crown.
bool crown_shows_over_parapet(const Tree& t, const BackgroundSite& site) {
  const Vec3 top = t.base + Vec3(0.0, 0.0, t.height_m);
  const Vec3 eye = site.walk_centre;
  const Vec2 d = Vec2(top.x() - eye.x(), top.y() - eye.y());
  const double dist = d.norm();
  const Vec2 u = d / dist;
  double exit = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 2; ++i)
    if (std::abs(u[i]) > 1e-9) exit = std::min(exit, ((u[i] > 0 ? site.roof_half_m : -site.roof_half_m) - eye[i]) / u[i]);
  const double line = eye.z() + (1.1 - eye.z()) * dist / exit;
  return top.z() - line > t.crown_half_height_m * 2.0 / 3.0;
}

std::vector<Building> draw_buildings(const BackgroundSite& site, double away, std::mt19937_64& rng) {
  const bool roof = site.setting == AntennaSetting::kRooftop;
  std::vector<Building> out(static_cast<std::size_t>(uniform_int(rng, 2, 6)));
  for (auto& b : out) {
    bool behind = false;
    const double alpha = draw_azimuth(away, rng, &behind);
    double distance = uniform(rng, 25.0, 150.0);
    b.width_m = uniform(rng, 10.0, 40.0), b.depth_m = uniform(rng, 10.0, 30.0);
    // Clear of the roof's corners (rooftop) or of the mast and its panels (ground).
    const double half_diagonal = 0.5 * std::hypot(b.width_m, b.depth_m);
    distance = std::max(distance, half_diagonal + (roof ? std::numbers::sqrt2 * site.roof_half_m + 2.0 : 8.0));
    b.centre_xy = distance * Vec2(std::sin(alpha), std::cos(alpha));
    b.base_z = -site.building_height_m;
    // Rooftop: taller than the roof, or nothing of it would show above the parapet.
    const double needed = sight_line_z(site, b.centre_xy) + 2.0 - b.base_z;
    b.height_m = draw_height(roof ? std::max(10.0, site.building_height_m + 3.0) : 10.0, 60.0, behind, needed, rng);
    b.yaw = alpha + uniform(rng, -deg2rad(30.0), deg2rad(30.0));
    Facade& f = b.facade;
    f.storey_m = uniform(rng, 3.0, 3.6), f.bay_m = uniform(rng, 1.5, 3.5);
    f.window_width_fraction = uniform(rng, 0.35, 0.7), f.window_height_fraction = uniform(rng, 0.4, 0.65);
    f.wall_reflectance = uniform(rng, 0.3, 0.7), f.glass_reflectance = uniform(rng, 0.1, 0.3);
    f.seed = rng();
  }
  return out;
}

Tree draw_tree(const BackgroundSite& site, double away, std::mt19937_64& rng) {
  const bool roof = site.setting == AntennaSetting::kRooftop;
  Tree t;
  bool behind = false;
  const double alpha = draw_azimuth(away, rng, &behind);
  // Ground: 10–40 m from the mast; rooftop: in the street beyond the roof's corners (crowns up
  // to 7 m wide).
  const double near = roof ? std::numbers::sqrt2 * site.roof_half_m + 9.0 : 10.0;
  const double distance = uniform(rng, near, std::max(roof ? 60.0 : 40.0, near + 1.0));
  t.base = distance * heading(alpha) + Vec3(0.0, 0.0, -site.building_height_m);
  // Right behind the antennas: the crown's upper half above the line of sight.
  const double needed = sight_line_z(site, t.base.head<2>()) - t.base.z() + 2.0;
  t.height_m = draw_height(6.0, 20.0, behind, needed, rng);
  t.crown_radius_m = t.height_m * uniform(rng, 0.2, 0.35);
  t.crown_half_height_m = t.height_m * uniform(rng, 0.25, 0.4);
  t.trunk_radius_m = 0.08 + 0.015 * t.height_m;
  t.reflectance = uniform(rng, 0.2, 0.3);
  t.blobs = uniform_int(rng, 1, 3);
  t.seed = rng();
  return t;
}

std::vector<Tree> draw_trees(const BackgroundSite& site, double away, std::mt19937_64& rng) {
  const int count = uniform_int(rng, 3, 10);
  std::vector<Tree> out;
  // A rooftop sees only the crowns that rise above its parapet: a few tries per tree.
  for (int k = 0; k < count; ++k)
    for (int attempt = 0; attempt < 8; ++attempt) {
      const Tree t = draw_tree(site, away, rng);
      if (site.setting == AntennaSetting::kRooftop && !crown_shows_over_parapet(t, site)) continue;
      out.push_back(t);
      break;
    }
  return out;
}

// A crown blob: the icosphere scaled to the ellipsoid (r, r, h) and pushed in and out by ±18 %
// of value noise over its directions, so that outlines are irregular like foliage.
model::Mesh blob_mesh(const model::Mesh& sphere, double r, double h, std::uint64_t seed) {
  model::Mesh m = sphere;
  for (Vec3& v : m.vertices) {
    const double bump = 1.0 + 0.18 * value_noise(2.5 * v, seed);
    v = Vec3(r * v.x(), r * v.y(), h * v.z()) * bump;
  }
  return m;
}

MeshObject tree_object(const Tree& t, const model::Mesh& sphere, const std::string& name) {
  MeshObject obj;
  obj.name = name;
  obj.p_world_object = t.base;
  obj.albedo = 1.0;  // the reflectance function gives the absolute value
  const double crown_z = t.height_m - t.crown_half_height_m;
  append_part(obj, cylinder_mesh(Vec3::Zero(), Vec3(0.0, 0.0, crown_z), t.trunk_radius_m, 10), deg2rad(40.0));
  std::mt19937_64 rng(mix_bits(t.seed));
  for (int k = 0; k < t.blobs; ++k) {
    const double s = k == 0 ? 1.0 : uniform(rng, 0.6, 0.9);
    const Vec3 offset = k == 0 ? Vec3::Zero()
                               : Vec3(uniform(rng, -0.4, 0.4) * t.crown_radius_m, uniform(rng, -0.4, 0.4) * t.crown_radius_m,
                                      uniform(rng, -0.3, 0.2) * t.crown_half_height_m);
    model::Mesh blob = blob_mesh(sphere, s * t.crown_radius_m, s * t.crown_half_height_m, t.seed + k);
    for (Vec3& v : blob.vertices) v += offset + Vec3(0.0, 0.0, crown_z);
    append_part(obj, blob, deg2rad(80.0));
  }
  // Leaves: ±35 % noise at 0.4 m and 0.12 m, within 0.15–0.35; the trunk a plain dark bark.
  const double trunk_r2 = std::pow(1.01 * t.trunk_radius_m, 2), crown_bottom = crown_z - t.crown_half_height_m;
  const double mean = t.reflectance;
  const std::uint64_t s1 = mix_bits(t.seed + 11), s2 = mix_bits(t.seed + 12);
  obj.reflectance = [=](const Vec3& p) {
    if (p.z() < crown_bottom && p.x() * p.x() + p.y() * p.y() <= trunk_r2) return 0.18;
    const double n = 0.25 * value_noise(p / 0.4, s1) + 0.1 * value_noise(p / 0.12, s2);
    return std::clamp(mean * (1.0 + n), 0.15, 0.35);
  };
  return obj;
}

}  // namespace

std::string to_string(BackgroundKind kind) {
  switch (kind) {
    case BackgroundKind::kSky:
      return "sky";
    case BackgroundKind::kBuildings:
      return "buildings";
    case BackgroundKind::kTrees:
      return "trees";
  }
  return "unknown";
}

BackgroundKind parse_background_kind(const std::string& name) {
  for (const auto k : {BackgroundKind::kSky, BackgroundKind::kBuildings, BackgroundKind::kTrees})
    if (to_string(k) == name) return k;
  throw InputError("--background", fmt::format("'{}' is not sky, buildings or trees", name));
}

Background draw_background(BackgroundKind kind, const BackgroundSite& site, std::mt19937_64& rng) {
  Background bg;
  bg.kind = kind;
  const double away = azimuth_of(-Vec3(site.walk_centre.x(), site.walk_centre.y(), 0.0));
  if (kind == BackgroundKind::kBuildings) bg.buildings = draw_buildings(site, away, rng);
  if (kind == BackgroundKind::kTrees) bg.trees = draw_trees(site, away, rng);
  return bg;
}

std::vector<TexturedPatch> background_patches(const Background& bg) {
  std::vector<TexturedPatch> out;
  for (std::size_t k = 0; k < bg.buildings.size(); ++k) {
    const Building& b = bg.buildings[k];
    double tile_m = 0.0;
    const auto facade = facade_texture(b.facade, &tile_m);
    const Vec3 y_axis = heading(b.yaw), x_axis = y_axis.cross(Vec3::UnitZ());
    const Vec3 centre(b.centre_xy.x(), b.centre_xy.y(), b.base_z);
    // Faces counter-clockwise from the front (towards the mast): patch x along the wall, y up.
    const std::array<std::pair<const char*, Vec3>, 4> faces{
        {{"front", -y_axis}, {"right", x_axis}, {"back", y_axis}, {"left", -x_axis}}};
    for (const auto& [face, normal] : faces) {
      const bool along_width = std::abs(normal.dot(y_axis)) > 0.5;
      const double length = along_width ? b.width_m : b.depth_m, offset = along_width ? b.depth_m / 2 : b.width_m / 2;
      TexturedPatch p;
      p.name = fmt::format("building-{}-{}", k + 1, face);
      const Vec3 along = Vec3::UnitZ().cross(normal);
      p.R_world_patch.col(0) = along;
      p.R_world_patch.col(1) = Vec3::UnitZ();
      p.R_world_patch.col(2) = along.cross(Vec3::UnitZ());
      p.p_world_patch = centre + offset * normal - 0.5 * length * along;
      p.min_xy = Eigen::Vector2d(0.0, 0.0);
      p.max_xy = Eigen::Vector2d(length, b.height_m);
      p.texture = facade;
      out.push_back(p);
    }
    TexturedPatch top;
    top.name = fmt::format("building-{}-roof", k + 1);
    top.R_world_patch.col(0) = x_axis;
    top.R_world_patch.col(1) = y_axis;
    top.R_world_patch.col(2) = Vec3::UnitZ();
    top.p_world_patch = centre + Vec3(0.0, 0.0, b.height_m);
    top.min_xy = Eigen::Vector2d(-b.width_m / 2, -b.depth_m / 2);
    top.max_xy = Eigen::Vector2d(b.width_m / 2, b.depth_m / 2);
    top.texture = procedural_texture(b.facade.seed + 1, 8.0, 256, 0.5 * b.facade.wall_reflectance + 0.1, 0.06);
    out.push_back(top);
  }
  return out;
}

std::vector<MeshObject> background_meshes(const Background& bg) {
  std::vector<MeshObject> out;
  const model::Mesh sphere = icosphere(2);
  for (std::size_t k = 0; k < bg.trees.size(); ++k)
    out.push_back(tree_object(bg.trees[k], sphere, fmt::format("tree-{}", k + 1)));
  return out;
}

model::Mesh icosphere(int subdivisions) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  model::Mesh m;
  for (const auto& v : {Vec3(-1, t, 0), Vec3(1, t, 0), Vec3(-1, -t, 0), Vec3(1, -t, 0), Vec3(0, -1, t), Vec3(0, 1, t),
                        Vec3(0, -1, -t), Vec3(0, 1, -t), Vec3(t, 0, -1), Vec3(t, 0, 1), Vec3(-t, 0, -1), Vec3(-t, 0, 1)})
    m.vertices.push_back(v.normalized());
  m.triangles = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                 {11, 10, 2}, {10, 7, 6}, {7, 1, 8},   {3, 9, 4},  {3, 4, 2},   {3, 2, 6}, {3, 6, 8},
                 {3, 8, 9},   {4, 9, 5},  {2, 4, 11},  {6, 2, 10}, {8, 6, 7},   {9, 8, 1}};
  for (int s = 0; s < subdivisions; ++s) {
    std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> midpoint;
    auto mid = [&](std::uint32_t a, std::uint32_t b) {
      const std::pair<std::uint32_t, std::uint32_t> key = std::minmax(a, b);
      const auto it = midpoint.find(key);
      if (it != midpoint.end()) return it->second;
      m.vertices.push_back((m.vertices[a] + m.vertices[b]).normalized());
      const auto id = static_cast<std::uint32_t>(m.vertices.size() - 1);
      midpoint.emplace(key, id);
      return id;
    };
    std::vector<std::array<std::uint32_t, 3>> next;
    for (const auto& f : m.triangles) {
      const std::uint32_t a = mid(f[0], f[1]), b = mid(f[1], f[2]), c = mid(f[2], f[0]);
      next.push_back({f[0], a, c});
      next.push_back({f[1], b, a});
      next.push_back({f[2], c, b});
      next.push_back({a, b, c});
    }
    m.triangles = std::move(next);
  }
  return m;
}

}  // namespace antpose::sim
