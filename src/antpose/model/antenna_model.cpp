#include "antpose/model/antenna_model.hpp"

#include <array>
#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <stdexcept>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <fmt/ranges.h>

#include "antpose/core/error.hpp"

namespace antpose::model {
namespace fs = std::filesystem;

namespace {

// A box file fits its mesh when its centre lies within the mesh's bounding box (grown by a
// quarter of its size, for brackets and poles scanned with the panel) and its diagonal is within
// a factor of 10 of the mesh's. Both fail for a box in other units or other coordinates.
constexpr double kBoxCentreMargin = 0.25;
constexpr double kBoxDiagonalRatio = 10.0;

std::string model_name(const fs::path& file) {
  fs::path name = file.filename();
  if (name.extension() == ".gz" || name.extension() == ".GZ") name = name.stem();
  return name.stem().string();
}

void check_box_fits_mesh(const Mesh& mesh, const AntennaBox& box, const fs::path& box_file) {
  const auto [lo, hi] = bounding_box(mesh);
  const Vec3 margin = kBoxCentreMargin * (hi - lo);
  const Vec3 centre_mesh = box.T_antenna_mesh.inverse().translation();
  const double box_diagonal = box.size_m.norm(), mesh_diagonal = (hi - lo).norm();
  const bool inside =
      (centre_mesh.array() >= (lo - margin).array()).all() && (centre_mesh.array() <= (hi + margin).array()).all();
  const double ratio = box_diagonal / std::max(mesh_diagonal, 1e-12);
  if (inside && ratio < kBoxDiagonalRatio && ratio > 1.0 / kBoxDiagonalRatio) return;
  throw InputError(
      box_file,
      fmt::format("the box does not fit the mesh: box centre ({:.4g}) and diagonal {:.4g} m, mesh "
                  "bounding box ({:.4g}) to ({:.4g}), diagonal {:.4g} m; the box file must be in the "
                  "mesh's coordinates and units",
                  fmt::join(centre_mesh, ", "), box_diagonal, fmt::join(lo, ", "), fmt::join(hi, ", "), mesh_diagonal));
}

[[noreturn]] void refuse_without_box(const Mesh& mesh, const fs::path& mesh_file) {
  const AntennaBox pca = principal_axes_box(mesh);
  throw InputError(mesh_file,
                   fmt::format("a box file is needed to place this mesh in the antenna frame: its shape gives the "
                               "long axis (its principal axes span about {:.3f} x {:.3f} x {:.3f} m, longest last) but "
                               "not which face is the radome, nor which end is the top. Give the eight corners A..H "
                               "of a box fitted to the panel (docs/antenna-models.md), or declare the mesh canonical "
                               "if it is already in the antenna frame (y out of the radome, z up the panel)",
                               pca.size_m.x(), pca.size_m.y(), pca.size_m.z()));
}

// Area-weighted mean and second moment of the surface, about `origin` (for accuracy far from 0).
// For a triangle (a, b, c) of area A: ∫ p dA = A s/3, ∫ p pᵀ dA = A/12 (Σ v vᵀ + s sᵀ), s = a+b+c.
std::pair<Vec3, Mat3> surface_moments(const Mesh& mesh, const Vec3& origin) {
  double area = 0;
  Vec3 first = Vec3::Zero();
  Mat3 second = Mat3::Zero();
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    const Vec3 a = mesh.vertices[t[0]] - origin, b = mesh.vertices[t[1]] - origin, c = mesh.vertices[t[2]] - origin;
    const double A = triangle_area(mesh, i);
    const Vec3 s = a + b + c;
    area += A;
    first += A * s / 3.0;
    second += A / 12.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + s * s.transpose());
  }
  if (area <= 0) {  // no surface: the vertices, equally weighted
    for (const auto& v : mesh.vertices) first += v - origin, second += (v - origin) * (v - origin).transpose();
    area = static_cast<double>(mesh.vertices.size());
  }
  const Vec3 mean = first / area;
  return {mean + origin, second / area - mean * mean.transpose()};
}

// --- parametric panel -------------------------------------------------------------------------

void validate(const PanelSpec& s) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(s.width_m) || !positive(s.depth_m) || !positive(s.height_m))
    throw std::invalid_argument(fmt::format("panel size {} x {} x {} m (width x depth x height): all must be > 0",
                                            s.width_m, s.depth_m, s.height_m));
  const double half = 0.5 * std::min(s.width_m, s.depth_m);
  if (!(s.edge_radius_m >= 0 && s.edge_radius_m < half))
    throw std::invalid_argument(
        fmt::format("panel edge radius {} m: must be ≥ 0 and below half the smaller of width and depth ({} m)",
                    s.edge_radius_m, half));
  if (s.arc_segments < 1 || s.arc_segments > 64)
    throw std::invalid_argument(fmt::format("panel arc_segments = {}: must be 1..64", s.arc_segments));
  if (!(s.end_cap_height_m >= 0 && s.end_cap_height_m < s.height_m / 2 && s.end_cap_rim_m >= 0 &&
        s.end_cap_rim_m <= 0.05))
    throw std::invalid_argument(fmt::format(
        "panel end caps {} m long with a rim of {} m: the length must be ≥ 0 and below half the height ({} m), "
        "the rim 0 .. 0.05 m",
        s.end_cap_height_m, s.end_cap_rim_m, s.height_m / 2));
  if (!s.bracket) return;
  if (!positive(s.bracket_width_m) || !positive(s.bracket_depth_m) || !positive(s.bracket_height_m))
    throw std::invalid_argument("panel bracket size: width, depth and height must be > 0");
  const double flat = s.width_m - 2 * s.edge_radius_m;
  if (s.bracket_width_m >= flat)
    throw std::invalid_argument(
        fmt::format("panel bracket width {} m: must be below the flat part of the back plate "
                    "(width − 2 · edge radius = {} m)",
                    s.bracket_width_m, flat));
  const double f = s.bracket_end_fraction;
  if (!(f > 0 && f < 0.5))
    throw std::invalid_argument(
        fmt::format("panel bracket end fraction {}: the brackets' centres must lie strictly between the ends "
                    "and the middle (0 < fraction < 0.5)",
                    f));
  // Each bracket between its end and the middle: height below 2 f h (its end) and (1 − 2 f) h
  // (the other bracket); half the height for brackets at 1/4 and 3/4.
  const double limit = std::min(2 * f, 1 - 2 * f) * s.height_m;
  if (s.bracket_height_m >= limit)
    throw std::invalid_argument(
        fmt::format("panel bracket height {} m: must be below {} m so that the two brackets, centred {} of the "
                    "height from each end, neither touch nor overhang the ends",
                    s.bracket_height_m, limit, f));
}

// Cross-section of the panel in the x–y plane, counter-clockwise seen from +z (so that the side
// faces wind outwards). With brackets it starts with the two points where the bracket meets the
// back plate, so that segment 0 is the part of the back plate that the brackets cover.
std::vector<Vec2> cross_section(const PanelSpec& s) {
  std::vector<Vec2> ring;
  const double r = s.edge_radius_m, cx = s.width_m / 2 - r, cy = s.depth_m / 2 - r;
  if (s.bracket) ring = {Vec2(-s.bracket_width_m / 2, -s.depth_m / 2), Vec2(s.bracket_width_m / 2, -s.depth_m / 2)};
  // Corner centres right-back, right-front, left-front, left-back; each arc turns 90°.
  const Vec2 centres[4] = {Vec2(cx, -cy), Vec2(cx, cy), Vec2(-cx, cy), Vec2(-cx, -cy)};
  for (int k = 0; k < 4; ++k) {
    if (r == 0) {
      ring.push_back(centres[k]);
      continue;
    }
    for (int j = 0; j <= s.arc_segments; ++j) {
      const double angle = (k - 1 + static_cast<double>(j) / s.arc_segments) * std::numbers::pi / 2;
      ring.push_back(centres[k] + r * Vec2(std::cos(angle), std::sin(angle)));
    }
  }
  return ring;
}

// Builds a mesh face by face; each face is wound so that its normal points along `outward`.
class MeshBuilder {
 public:
  std::uint32_t vertex(const Vec3& p) {
    mesh_.vertices.push_back(p);
    return static_cast<std::uint32_t>(mesh_.vertices.size() - 1);
  }
  const Vec3& at(std::uint32_t i) const { return mesh_.vertices[i]; }

  void triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c, const Vec3& outward) {
    const Vec3 n = (at(b) - at(a)).cross(at(c) - at(a));
    if (n.dot(outward) >= 0)
      mesh_.triangles.push_back({a, b, c});
    else
      mesh_.triangles.push_back({a, c, b});
  }
  /// A planar quad a b c d in cyclic order.
  void quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d, const Vec3& outward) {
    triangle(a, b, c, outward);
    triangle(a, c, d, outward);
  }
  Mesh take() { return std::move(mesh_); }

 private:
  Mesh mesh_;
};

void add_bracket(MeshBuilder& mb, const std::array<std::uint32_t, 4>& hole, double depth_m) {
  // hole: back-plate vertices (−x, low), (+x, low), (+x, high), (−x, high).
  std::array<std::uint32_t, 4> outer;
  Vec3 centre = Vec3::Zero();
  for (int k = 0; k < 4; ++k) {
    outer[k] = mb.vertex(mb.at(hole[k]) - Vec3(0, depth_m, 0));
    centre += (mb.at(hole[k]) + mb.at(outer[k])) / 8.0;
  }
  for (int k = 0; k < 4; ++k) {
    const int n = (k + 1) % 4;
    const Vec3 mid = (mb.at(hole[k]) + mb.at(hole[n]) + mb.at(outer[n]) + mb.at(outer[k])) / 4.0;
    mb.quad(hole[k], hole[n], outer[n], outer[k], mid - centre);
  }
  mb.quad(outer[0], outer[1], outer[2], outer[3], -Vec3::UnitY());
}

Mesh panel_mesh(const PanelSpec& s) {
  const std::vector<Vec2> ring = cross_section(s);
  const std::size_t n = ring.size();
  const double h = s.height_m, bh = s.bracket_height_m, zb = (0.5 - s.bracket_end_fraction) * h;
  std::vector<double> levels = {-h / 2, h / 2};
  if (s.bracket) levels = {-h / 2, -zb - bh / 2, -zb + bh / 2, zb - bh / 2, zb + bh / 2, h / 2};
  const auto is_bracket_band = [&](std::size_t band) { return s.bracket && (band == 1 || band == 3); };

  MeshBuilder mb;
  std::vector<std::vector<std::uint32_t>> id(levels.size());
  for (std::size_t k = 0; k < levels.size(); ++k)
    for (const Vec2& p : ring) id[k].push_back(mb.vertex(Vec3(p.x(), p.y(), levels[k])));
  for (std::size_t k = 0; k + 1 < levels.size(); ++k)
    for (std::size_t i = 0; i < n; ++i) {
      if (i == 0 && is_bracket_band(k)) {
        add_bracket(mb, {id[k][0], id[k][1], id[k + 1][1], id[k + 1][0]}, s.bracket_depth_m);
        continue;
      }
      const std::size_t j = (i + 1) % n;
      const Vec2 mid = (ring[i] + ring[j]) / 2;  // the section is convex around the axis
      mb.quad(id[k][i], id[k][j], id[k + 1][j], id[k + 1][i], Vec3(mid.x(), mid.y(), 0));
    }
  const std::uint32_t bottom = mb.vertex(Vec3(0, 0, -h / 2)), top = mb.vertex(Vec3(0, 0, h / 2));
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t j = (i + 1) % n;
    mb.triangle(bottom, id.front()[i], id.front()[j], -Vec3::UnitZ());
    mb.triangle(top, id.back()[i], id.back()[j], Vec3::UnitZ());
  }
  return mb.take();
}

// The named built-ins; any other datasheet box is parsed from its name (datasheet_box).
constexpr const char* kBuiltinPanels[] = {"panel-1310x300x160", "thesis-1310x159x80", "panel-2000x300x150"};

// "panel-<h>x<w>x<d>" or "thesis-<h>x<w>x<d>" with whole millimetres: {h, w, d} in mm.
std::optional<std::array<int, 3>> datasheet_box(const std::string& name, const std::string& prefix) {
  if (name.rfind(prefix, 0) != 0) return std::nullopt;
  std::array<int, 3> mm{};
  std::size_t at = prefix.size();
  for (std::size_t i = 0; i < 3; ++i) {
    std::size_t end = at;
    while (end < name.size() && end - at < 5 && std::isdigit(static_cast<unsigned char>(name[end]))) ++end;
    if (end == at || name[at] == '0') return std::nullopt;
    mm[i] = std::stoi(name.substr(at, end - at));
    if (i < 2 && (end >= name.size() || name[end] != 'x')) return std::nullopt;
    at = end + (i < 2 ? 1 : 0);
  }
  if (at != name.size()) return std::nullopt;
  return mm;
}

// The box of a built-in name: the thesis's panel, or a datasheet box within the ranges.
std::optional<std::array<int, 3>> builtin_box(const std::string& name) {
  if (name == "thesis-1310x159x80") return datasheet_box(name, "thesis-");
  const auto mm = datasheet_box(name, "panel-");
  if (mm && (*mm)[0] >= 300 && (*mm)[0] <= 4000 && (*mm)[1] >= 100 && (*mm)[1] <= 800 && (*mm)[2] >= 50 &&
      (*mm)[2] <= 400 && (*mm)[2] <= (*mm)[1])
    return mm;
  return std::nullopt;
}

AntennaModel panel_from_box(const std::string& name, const std::array<int, 3>& mm) {
  PanelSpec spec;
  spec.height_m = mm[0] / 1000.0, spec.width_m = mm[1] / 1000.0, spec.depth_m = mm[2] / 1000.0;
  // A panel too narrow for the default brackets: leave 2 cm of the back plate's flat part.
  const double flat = spec.width_m - 2 * spec.edge_radius_m;
  if (spec.bracket_width_m >= flat) spec.bracket_width_m = flat - 0.02;
  AntennaModel model = parametric_panel(spec);
  model.name = name;
  return model;
}

}  // namespace

AntennaBox principal_axes_box(const Mesh& mesh) {
  if (mesh.vertices.empty()) throw std::invalid_argument("principal_axes_box: empty mesh");
  const auto [lo, hi] = bounding_box(mesh);
  const auto [mean, cov] = surface_moments(mesh, (lo + hi) / 2);
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);  // eigenvalues ascending
  const Vec3 z = eig.eigenvectors().col(2);            // largest spread: the long axis
  const Vec3 y = eig.eigenvectors().col(0);            // smallest: the depth
  Mat3 rows;
  rows.row(0) = y.cross(z).transpose();
  rows.row(1) = y.transpose();
  rows.row(2) = z.transpose();
  Vec3 pmin = Vec3::Constant(std::numeric_limits<double>::infinity()), pmax = -pmin;
  for (const auto& v : mesh.vertices) {
    const Vec3 p = rows * (v - mean);
    pmin = pmin.cwiseMin(p), pmax = pmax.cwiseMax(p);
  }
  AntennaBox box;
  box.T_antenna_mesh.linear() = rows;
  box.T_antenna_mesh.translation() = -(rows * mean) - (pmin + pmax) / 2;
  box.size_m = pmax - pmin;
  return box;
}

AntennaModel load_antenna_model(const fs::path& mesh_file, const std::optional<fs::path>& box_file, Units units,
                                bool assume_canonical) {
  const Mesh mesh = read_mesh(mesh_file, units);
  if (mesh.triangles.empty())
    throw InputError(mesh_file,
                     "the mesh has no faces (a point cloud): an antenna model needs triangles, to sample "
                     "its surface and normals from");
  // Faces of no area (repeated or collinear corners) give no surface to sample: refused here
  // rather than after the reconstruction has run.
  const auto extent = bounding_box(mesh);
  const double size = (extent.second - extent.first).maxCoeff();
  if (!(surface_area(mesh) > 1e-6 * size * size))
    throw InputError(mesh_file, fmt::format("the mesh's {} faces have no area (their corners repeat or lie on a line): "
                                            "an antenna model needs a surface",
                                            mesh.triangles.size()));
  AntennaModel model;
  model.name = model_name(mesh_file);
  if (box_file) {
    const AntennaBox box = read_box_file(*box_file, units);
    check_box_fits_mesh(mesh, box, *box_file);
    model.T_antenna_mesh = box.T_antenna_mesh;
    model.size_m = box.size_m;
  } else if (assume_canonical) {
    const auto [lo, hi] = bounding_box(mesh);
    model.T_antenna_mesh = Iso3(Eigen::Translation3d(-(lo + hi) / 2));
    model.size_m = hi - lo;
  } else {
    refuse_without_box(mesh, mesh_file);
  }
  model.mesh_antenna = transformed(mesh, model.T_antenna_mesh);
  return model;
}

std::vector<Mesh> end_cap_meshes(const PanelSpec& spec) {
  validate(spec);
  if (spec.end_cap_height_m <= 0.0) return {};
  PanelSpec cap;
  const double rim = spec.end_cap_rim_m;
  cap.width_m = spec.width_m + 2 * rim, cap.depth_m = spec.depth_m + 2 * rim, cap.height_m = spec.end_cap_height_m;
  cap.edge_radius_m = spec.edge_radius_m + rim;
  cap.arc_segments = spec.arc_segments;
  cap.bracket = false;
  const Mesh mesh = panel_mesh(cap);
  std::vector<Mesh> caps;
  for (const double side : {-1.0, 1.0})
    caps.push_back(transformed(mesh, Iso3(Eigen::Translation3d(0.0, 0.0, side * (spec.height_m - cap.height_m) / 2))));
  return caps;
}

Vec3 outline_box(const AntennaModel& model) {
  const double rim = model.panel && model.panel->end_cap_height_m > 0 ? model.panel->end_cap_rim_m : 0.0;
  return model.size_m + Vec3(2 * rim, 2 * rim, 0.0);
}

AntennaModel parametric_panel(const PanelSpec& spec) {
  validate(spec);
  AntennaModel model;
  model.name =
      fmt::format("parametric-{:.0f}x{:.0f}x{:.0f}", spec.height_m * 1e3, spec.width_m * 1e3, spec.depth_m * 1e3);
  model.mesh_antenna = panel_mesh(spec);
  // Caps flush with the radome change nothing of its shape.
  if (spec.end_cap_rim_m > 0)
    for (const Mesh& cap : end_cap_meshes(spec)) append_mesh(model.mesh_antenna, cap);
  model.size_m = Vec3(spec.width_m, spec.depth_m, spec.height_m);
  model.panel = std::make_shared<const PanelSpec>(spec);
  return model;
}

AntennaModel builtin_panel(const std::string& name) {
  if (const auto mm = builtin_box(name)) return panel_from_box(name, *mm);
  throw InputError(fs::path(), fmt::format("unknown built-in antenna model '{}': expected panel-<h>x<w>x<d>, a "
                                           "datasheet box height x width x depth in whole mm (h 300..4000, w "
                                           "100..800, d 50..400, d <= w; e.g. panel-1850x280x120), or one of: {}",
                                           name, fmt::join(builtin_panel_names(), ", ")));
}

bool is_builtin_panel(const std::string& name) { return builtin_box(name).has_value(); }

std::vector<std::string> builtin_panel_names() { return {std::begin(kBuiltinPanels), std::end(kBuiltinPanels)}; }

}  // namespace antpose::model
