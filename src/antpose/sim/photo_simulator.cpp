#include "antpose/sim/photo_simulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace antpose::sim {

// --- texture -----------------------------------------------------------------------------

Texture Texture::from_image(const cv::Mat& reflectance, const Eigen::Matrix<double, 2, 3>& texel_from_patch,
                            bool repeat, int max_levels) {
  if (reflectance.empty() || reflectance.channels() != 1)
    throw std::invalid_argument("Texture::from_image: expected a non-empty single-channel image");
  if (std::abs(texel_from_patch.leftCols<2>().determinant()) < 1e-12)
    throw std::invalid_argument("Texture::from_image: texel_from_patch is not invertible");
  cv::Mat base;
  if (reflectance.depth() == CV_8U)
    reflectance.convertTo(base, CV_32F, 1.0 / 255.0);
  else
    reflectance.convertTo(base, CV_32F);
  // Number of levels: down to about 4 texels on the short side.
  int count = 1;
  while (count < max_levels && (std::min(base.cols, base.rows) >> count) >= 4) ++count;
  const int block = 1 << (count - 1);
  const int pad_x = (block - base.cols % block) % block, pad_y = (block - base.rows % block) % block;
  if (repeat && (pad_x != 0 || pad_y != 0))
    throw std::invalid_argument(
        fmt::format("Texture::from_image: a repeating texture of {}x{} texels must be a multiple of {}", base.cols,
                    base.rows, block));
  if (pad_x != 0 || pad_y != 0) cv::copyMakeBorder(base, base, 0, pad_y, 0, pad_x, cv::BORDER_REPLICATE);
  Texture t;
  t.texel_from_patch = texel_from_patch;
  t.repeat = repeat;
  t.levels.push_back(base);
  for (int k = 1; k < count; ++k) {
    cv::Mat next;
    // Exact halving: INTER_AREA is the 2 x 2 box average, centred like the texels it replaces.
    cv::resize(t.levels.back(), next, cv::Size(t.levels.back().cols / 2, t.levels.back().rows / 2), 0, 0,
               cv::INTER_AREA);
    t.levels.push_back(next);
  }
  return t;
}

std::optional<Vec2> project_world(const camera::CameraIntrinsics& intrinsics, const CameraPose& pose,
                                  const Vec3& p_world) {
  return intrinsics.project(pose.R_world_camera.transpose() * (p_world - pose.p_world_camera));
}

// --- renderer ----------------------------------------------------------------------------

PhotoRenderer::PhotoRenderer(const camera::CameraIntrinsics& intrinsics, int supersampling)
    : intrinsics_(intrinsics), supersampling_(supersampling) {
  if (const auto why = intrinsics.invalid_reason()) throw std::invalid_argument("PhotoRenderer: intrinsics " + *why);
  if (supersampling < 1 || supersampling > 8)
    throw std::invalid_argument(fmt::format("PhotoRenderer: supersampling {} is outside 1..8", supersampling));
  const int W = intrinsics.width, H = intrinsics.height;
  xy_.create(H, W, CV_32FC2);
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      auto* row = xy_.ptr<cv::Vec2f>(v);
      for (int u = 0; u < W; ++u) {
        const Vec2 d((u - intrinsics.cx) / intrinsics.fx, (v - intrinsics.cy) / intrinsics.fy);
        const Vec2 xy = intrinsics.has_distortion() ? intrinsics.undistort(d) : d;
        row[u] = cv::Vec2f(static_cast<float>(xy.x()), static_cast<float>(xy.y()));
      }
    }
  });
  // Jacobian by central differences of the grid (one-sided at the border); the undistortion is
  // smooth on the scale of a pixel, so this is exact to O(pixel²) of its curvature.
  jacobian_.create(H, W, CV_32FC4);
  for (int v = 0; v < H; ++v) {
    const int v0 = std::max(v - 1, 0), v1 = std::min(v + 1, H - 1);
    const auto* up = xy_.ptr<cv::Vec2f>(v0);
    const auto* down = xy_.ptr<cv::Vec2f>(v1);
    const auto* row = xy_.ptr<cv::Vec2f>(v);
    auto* out = jacobian_.ptr<cv::Vec4f>(v);
    for (int u = 0; u < W; ++u) {
      const int u0 = std::max(u - 1, 0), u1 = std::min(u + 1, W - 1);
      const cv::Vec2f du = (row[u1] - row[u0]) / static_cast<float>(u1 - u0);
      const cv::Vec2f dv = (down[u] - up[u]) / static_cast<float>(v1 - v0);
      out[u] = cv::Vec4f(du[0], dv[0], du[1], dv[1]);
    }
  }
  // Normalised bounding box of every sample of each tile: the pixel centres widened by half a
  // pixel through the local Jacobian (the samples lie within ±0.5 px of their pixel centre).
  tiles_x_ = (W + kTile - 1) / kTile, tiles_y_ = (H + kTile - 1) / kTile;
  tile_box_.assign(static_cast<std::size_t>(tiles_x_) * static_cast<std::size_t>(tiles_y_),
                   {std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                    std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()});
  for (int v = 0; v < H; ++v) {
    const auto* row = xy_.ptr<cv::Vec2f>(v);
    const auto* J = jacobian_.ptr<cv::Vec4f>(v);
    for (int u = 0; u < W; ++u) {
      auto& b = tile_box_[static_cast<std::size_t>((v / kTile) * tiles_x_ + u / kTile)];
      const float rx = 0.5f * (std::abs(J[u][0]) + std::abs(J[u][1])),
                  ry = 0.5f * (std::abs(J[u][2]) + std::abs(J[u][3]));
      b[0] = std::min(b[0], row[u][0] - rx), b[1] = std::max(b[1], row[u][0] + rx);
      b[2] = std::min(b[2], row[u][1] - ry), b[3] = std::max(b[3], row[u][1] + ry);
    }
  }
}

std::vector<std::array<Vec3, 3>> smooth_corner_normals(const model::Mesh& mesh, double crease_rad) {
  const std::size_t nt = mesh.triangles.size();
  // Weld vertices at the same position (to 1e-7 m) so that split vertices still smooth.
  std::map<std::array<long long, 3>, std::uint32_t> weld;
  std::vector<std::uint32_t> canon(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& p = mesh.vertices[i];
    const std::array<long long, 3> key{std::llround(p.x() * 1e7), std::llround(p.y() * 1e7), std::llround(p.z() * 1e7)};
    canon[i] = weld.emplace(key, static_cast<std::uint32_t>(i)).first->second;
  }
  // Corner angles weight the face normals (Thürmer & Wüthrich 1998): unlike area weights they do
  // not depend on how a quad was split into triangles, so a cylinder's normals come out radial.
  std::vector<Vec3> unit(nt, Vec3::Zero());
  std::vector<std::array<double, 3>> angle(nt, {0.0, 0.0, 0.0});
  std::vector<std::vector<std::pair<std::uint32_t, std::uint32_t>>> around(mesh.vertices.size());  // (triangle, corner)
  for (std::size_t t = 0; t < nt; ++t) {
    const auto& tri = mesh.triangles[t];
    for (const auto i : tri)
      if (i >= mesh.vertices.size())
        throw std::invalid_argument("smooth_corner_normals: a triangle indexes outside the vertices");
    const Vec3& a = mesh.vertices[tri[0]];
    const Vec3 n = (mesh.vertices[tri[1]] - a).cross(mesh.vertices[tri[2]] - a);
    if (n.norm() > 0.0) unit[t] = n.normalized();
    for (std::uint32_t k = 0; k < 3; ++k) {
      const Vec3 e1 = mesh.vertices[tri[(k + 1) % 3]] - mesh.vertices[tri[k]];
      const Vec3 e2 = mesh.vertices[tri[(k + 2) % 3]] - mesh.vertices[tri[k]];
      angle[t][k] = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
      around[canon[tri[k]]].emplace_back(static_cast<std::uint32_t>(t), k);
    }
  }
  const double cos_crease = std::cos(crease_rad);
  std::vector<std::array<Vec3, 3>> out(nt);
  for (std::size_t t = 0; t < nt; ++t)
    for (std::size_t k = 0; k < 3; ++k) {
      Vec3 sum = Vec3::Zero();
      for (const auto& [o, c] : around[canon[mesh.triangles[t][k]]])
        if (unit[o].dot(unit[t]) >= cos_crease) sum += angle[o][c] * unit[o];
      out[t][k] = sum.norm() > 0.0 ? Vec3(sum.normalized()) : unit[t];
    }
  return out;
}

void append_part(MeshObject& object, const model::Mesh& part, double crease_rad) {
  if (object.corner_normals.size() != object.mesh.triangles.size())
    throw std::invalid_argument(fmt::format("append_part: mesh '{}' is flat-shaded", object.name));
  const auto normals = smooth_corner_normals(part, crease_rad);
  model::append_mesh(object.mesh, part);
  object.corner_normals.insert(object.corner_normals.end(), normals.begin(), normals.end());
}

namespace {

// Per-photo geometry of one patch, in floats for the inner loop.
struct PatchView {
  std::array<float, 9> R{};  // R_patch_camera, row-major
  std::array<float, 3> o{};  // camera centre in the patch frame
  float min_a = 0, min_b = 0, max_a = 0, max_b = 0;
  std::array<float, 6> A{};  // texel_from_patch
  float shade = 0;
  const Texture* texture = nullptr;
  // Bounding box of the visible part in normalised image coordinates (x, y).
  float bx0 = 0, bx1 = 0, by0 = 0, by1 = 0;
};

// Bounding box in normalised coordinates of the part of the patch in front of the camera:
// the rectangle clipped against the plane Z = z_near (Sutherland–Hodgman), then projected
// (a plane's image is the convex hull of its vertices' images). False when nothing is in front.
template <std::size_t N, class View>
bool normalised_bbox(const std::array<Vec3, N>& corners_camera, View& pv) {
  constexpr double z_near = 1e-3;
  std::vector<Vec3> poly;
  for (std::size_t i = 0; i < N; ++i) {
    const Vec3& a = corners_camera[i];
    const Vec3& b = corners_camera[(i + 1) % N];
    const bool ina = a.z() >= z_near, inb = b.z() >= z_near;
    if (ina) poly.push_back(a);
    if (ina != inb) poly.push_back(a + (z_near - a.z()) / (b.z() - a.z()) * (b - a));
  }
  if (poly.empty()) return false;
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const Vec3& p : poly) {
    x0 = std::min(x0, p.x() / p.z()), x1 = std::max(x1, p.x() / p.z());
    y0 = std::min(y0, p.y() / p.z()), y1 = std::max(y1, p.y() / p.z());
  }
  constexpr double big = 1e6;
  pv.bx0 = static_cast<float>(std::max(x0, -big)), pv.bx1 = static_cast<float>(std::min(x1, big));
  pv.by0 = static_cast<float>(std::max(y0, -big)), pv.by1 = static_cast<float>(std::min(y1, big));
  return true;
}

inline float bilinear(const cv::Mat& img, float x, float y, bool repeat) {
  // x, y in centre coordinates (texel (i, j) centred at (i, j)).
  const float fx0 = std::floor(x), fy0 = std::floor(y);
  const float ax = x - fx0, ay = y - fy0;
  int x0 = static_cast<int>(fx0), y0 = static_cast<int>(fy0);
  int x1 = x0 + 1, y1 = y0 + 1;
  const int W = img.cols, H = img.rows;
  if (repeat) {
    x0 = ((x0 % W) + W) % W, x1 = ((x1 % W) + W) % W;
    y0 = ((y0 % H) + H) % H, y1 = ((y1 % H) + H) % H;
  } else {
    x0 = std::clamp(x0, 0, W - 1), x1 = std::clamp(x1, 0, W - 1);
    y0 = std::clamp(y0, 0, H - 1), y1 = std::clamp(y1, 0, H - 1);
  }
  const float* r0 = img.ptr<float>(y0);
  const float* r1 = img.ptr<float>(y1);
  const float top = r0[x0] + ax * (r0[x1] - r0[x0]);
  const float bottom = r1[x0] + ax * (r1[x1] - r1[x0]);
  return top + ay * (bottom - top);
}

// Trilinear lookup at texel (edge) coordinates (tx, ty) of level 0 and fractional level.
inline float trilinear(const Texture& t, float tx, float ty, float level) {
  const int top = static_cast<int>(t.levels.size()) - 1;
  level = std::clamp(level, 0.0f, static_cast<float>(top));
  const int l0 = static_cast<int>(level);
  const float f = level - static_cast<float>(l0);
  auto at = [&](int l) {
    const float s = 1.0f / static_cast<float>(1 << l);
    return bilinear(t.levels[static_cast<std::size_t>(l)], tx * s - 0.5f, ty * s - 0.5f, t.repeat);
  };
  const float v0 = at(l0);
  if (f < 1e-3f || l0 == top) return v0;
  return v0 + f * (at(l0 + 1) - v0);
}

}  // namespace

namespace {

// Per-photo geometry of one triangle: edge normals e_ij = v_i × v_j of its camera-frame
// vertices (d·e_ij ∝ the barycentric of the opposite vertex for the ray d), V = v0·(v1 × v2)
// (depth λ = V / Σ d·e_ij along d = (x, y, 1)), world corner normals, object-frame vertices.
struct TriangleView {
  std::array<float, 9> e{};  // e12, e20, e01 (opposite vertices 0, 1, 2)
  float V = 0;
  std::array<float, 9> n{};  // world shading normals at the corners (facing the camera)
  std::array<float, 9> p{};  // object-frame vertices
  int object = 0;            // index into Scene::meshes
  float bx0 = 0, bx1 = 0, by0 = 0, by1 = 0;
};

}  // namespace

double sky_radiance(const Lighting& lighting, const Vec3& direction_world) {
  if (!lighting.dome) return lighting.sky;
  const SkyDome& dome = *lighting.dome;
  const Vec3 d = direction_world.normalized();
  const double up = std::max(0.0, d.z());
  double radiance = dome.horizon + (dome.zenith - dome.horizon) * std::sqrt(up);
  if (dome.clouds && up > 0.02) {
    constexpr double kLayer = 1000.0;  // m
    const Texture& t = *dome.clouds;
    const double x = kLayer * d.x() / d.z(), y = kLayer * d.y() / d.z();
    const auto& A = t.texel_from_patch;
    const float tex = bilinear(t.levels.front(), static_cast<float>(A(0, 0) * x + A(0, 1) * y + A(0, 2)) - 0.5f,
                               static_cast<float>(A(1, 0) * x + A(1, 1) * y + A(1, 2)) - 0.5f, t.repeat);
    const double fade = std::clamp((up - 0.02) / 0.23, 0.0, 1.0);
    radiance *= 1.0 + fade * (2.0 * tex - 1.0);
  }
  return radiance;
}

cv::Mat PhotoRenderer::render(const std::vector<TexturedPatch>& patches, const CameraPose& pose,
                              const Lighting& lighting) const {
  Scene scene;
  scene.patches = patches;
  return render(scene, pose, lighting);
}

cv::Mat PhotoRenderer::render(const Scene& scene, const CameraPose& pose, const Lighting& lighting,
                              cv::Mat* object_ids) const {
  const auto& patches = scene.patches;
  const Mat3& R_wc = pose.R_world_camera;
  const Vec3& c_w = pose.p_world_camera;
  std::vector<PatchView> views;
  std::vector<int> view_id;  // object id of each view
  for (std::size_t pi = 0; pi < patches.size(); ++pi) {
    const auto& p = patches[pi];
    if (!p.texture || p.texture->levels.empty())
      throw std::invalid_argument(fmt::format("PhotoRenderer::render: patch '{}' has no texture", p.name));
    PatchView pv;
    const Mat3 R_pc = p.R_world_patch.transpose() * R_wc;
    const Vec3 o = p.R_world_patch.transpose() * (c_w - p.p_world_patch);
    if (std::abs(o.z()) < 1e-9) continue;  // camera in the plane: the patch is seen edge-on
    for (int i = 0; i < 9; ++i) pv.R[static_cast<std::size_t>(i)] = static_cast<float>(R_pc(i / 3, i % 3));
    for (int i = 0; i < 3; ++i) pv.o[static_cast<std::size_t>(i)] = static_cast<float>(o[i]);
    pv.min_a = static_cast<float>(p.min_xy.x()), pv.min_b = static_cast<float>(p.min_xy.y());
    pv.max_a = static_cast<float>(p.max_xy.x()), pv.max_b = static_cast<float>(p.max_xy.y());
    for (int i = 0; i < 6; ++i)
      pv.A[static_cast<std::size_t>(i)] = static_cast<float>(p.texture->texel_from_patch(i / 3, i % 3));
    // Lambert on the side facing the camera (both sides are textured alike).
    Vec3 n = p.R_world_patch.col(2);
    if (n.dot(c_w - p.p_world_patch) < 0.0) n = -n;
    pv.shade = static_cast<float>(
        p.albedo * (lighting.ambient + lighting.direct * std::max(0.0, n.dot(lighting.towards_light_world))));
    pv.texture = p.texture.get();
    std::array<Vec3, 4> corners;
    const Eigen::Vector2d lo = p.min_xy, hi = p.max_xy;
    const std::array<Eigen::Vector2d, 4> uv = {lo, Eigen::Vector2d(hi.x(), lo.y()), hi,
                                               Eigen::Vector2d(lo.x(), hi.y())};
    for (std::size_t i = 0; i < 4; ++i)
      corners[i] = R_wc.transpose() * (p.p_world_patch + p.R_world_patch * Vec3(uv[i].x(), uv[i].y(), 0.0) - c_w);
    if (!normalised_bbox(corners, pv)) continue;
    views.push_back(pv);
    view_id.push_back(static_cast<int>(pi));
  }

  // Triangles in front of the camera, then binned into tiles (CSR lists).
  std::vector<TriangleView> tris;
  std::vector<std::array<float, 4>> object_box;  // per mesh: normalised bbox of its triangles
  for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
    const MeshObject& obj = scene.meshes[m];
    const bool smooth = !obj.corner_normals.empty();
    if (smooth && obj.corner_normals.size() != obj.mesh.triangles.size())
      throw std::invalid_argument(fmt::format("PhotoRenderer::render: mesh '{}' has {} corner normals for {} triangles",
                                              obj.name, obj.corner_normals.size(), obj.mesh.triangles.size()));
    const Mat3 R_co = R_wc.transpose() * obj.R_world_object;
    const Vec3 t_co = R_wc.transpose() * (obj.p_world_object - c_w);
    std::vector<Vec3> vc(obj.mesh.vertices.size());
    for (std::size_t i = 0; i < vc.size(); ++i) vc[i] = R_co * obj.mesh.vertices[i] + t_co;
    std::array<float, 4> box{std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                             std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity()};
    for (std::size_t t = 0; t < obj.mesh.triangles.size(); ++t) {
      const auto& tri = obj.mesh.triangles[t];
      if (tri[0] >= vc.size() || tri[1] >= vc.size() || tri[2] >= vc.size())
        throw std::invalid_argument(
            fmt::format("PhotoRenderer::render: mesh '{}' triangle {} indexes outside its vertices", obj.name, t));
      const std::array<Vec3, 3> v{vc[tri[0]], vc[tri[1]], vc[tri[2]]};
      const Vec3 face = (v[1] - v[0]).cross(v[2] - v[0]);
      if (!(face.squaredNorm() > 0.0)) continue;
      const double facing = face.dot(v[0]);  // > 0: the camera sees the back of the face
      if (facing == 0.0 || (obj.cull_back_faces && facing > 0.0)) continue;
      TriangleView tv;
      if (!normalised_bbox(v, tv)) continue;
      // Edge vectors in doubles, then rounded: a shared edge gets exactly negated vectors.
      const std::array<Vec3, 3> e{v[1].cross(v[2]), v[2].cross(v[0]), v[0].cross(v[1])};
      for (std::size_t k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i) tv.e[3 * k + static_cast<std::size_t>(i)] = static_cast<float>(e[k][i]);
      tv.V = static_cast<float>(v[0].dot(e[0]));
      const double flip = facing > 0.0 ? -1.0 : 1.0;  // a two-sided face seen from its back
      const Vec3 face_world = (obj.R_world_object * (obj.mesh.vertices[tri[1]] - obj.mesh.vertices[tri[0]])
                                                        .cross(obj.mesh.vertices[tri[2]] - obj.mesh.vertices[tri[0]]))
                                  .normalized();
      for (std::size_t k = 0; k < 3; ++k) {
        const Vec3 nk = flip * (smooth ? Vec3(obj.R_world_object * obj.corner_normals[t][k]) : face_world);
        const Vec3& pk = obj.mesh.vertices[tri[k]];
        for (int i = 0; i < 3; ++i) {
          tv.n[3 * k + static_cast<std::size_t>(i)] = static_cast<float>(nk[i]);
          tv.p[3 * k + static_cast<std::size_t>(i)] = static_cast<float>(pk[i]);
        }
      }
      tv.object = static_cast<int>(m);
      box[0] = std::min(box[0], tv.bx0), box[1] = std::max(box[1], tv.bx1);
      box[2] = std::min(box[2], tv.by0), box[3] = std::max(box[3], tv.by1);
      tris.push_back(tv);
    }
    object_box.push_back(box);
  }
  const std::size_t n_tiles = tile_box_.size();
  std::vector<std::uint32_t> tile_start(n_tiles + 1, 0), tile_tris;
  if (!tris.empty()) {
    auto overlaps = [](const std::array<float, 4>& a, float x0, float x1, float y0, float y1) {
      return a[1] >= x0 && a[0] <= x1 && a[3] >= y0 && a[2] <= y1;
    };
    // Triangles of one object are contiguous; test them only on tiles the object's box touches.
    std::vector<std::vector<std::uint32_t>> lists(n_tiles);
    std::size_t first = 0;
    for (std::size_t m = 0; m < scene.meshes.size(); ++m) {
      std::size_t last = first;
      while (last < tris.size() && tris[last].object == static_cast<int>(m)) ++last;
      if (last == first) continue;
      const auto& ob = object_box[m];
      for (std::size_t k = 0; k < n_tiles; ++k) {
        const auto& tb = tile_box_[k];
        if (!overlaps(tb, ob[0], ob[1], ob[2], ob[3])) continue;
        for (std::size_t t = first; t < last; ++t)
          if (overlaps(tb, tris[t].bx0, tris[t].bx1, tris[t].by0, tris[t].by1))
            lists[k].push_back(static_cast<std::uint32_t>(t));
      }
      first = last;
    }
    for (std::size_t k = 0; k < n_tiles; ++k)
      tile_start[k + 1] = tile_start[k] + static_cast<std::uint32_t>(lists[k].size());
    tile_tris.reserve(tile_start.back());
    for (const auto& l : lists) tile_tris.insert(tile_tris.end(), l.begin(), l.end());
  }
  const Eigen::Vector3f light = lighting.towards_light_world.cast<float>();
  const auto ambient = static_cast<float>(lighting.ambient), direct = static_cast<float>(lighting.direct);
  const int patch_count = static_cast<int>(patches.size());

  const int W = intrinsics_.width, H = intrinsics_.height, S = supersampling_;
  const float inv_s = 1.0f / static_cast<float>(S);
  const float log2_s = std::log2(static_cast<float>(S));
  const float sky = static_cast<float>(lighting.sky);
  const int centre_sample = (S / 2) * S + S / 2;
  cv::Mat out(H, W, CV_32FC1);
  if (object_ids) object_ids->create(H, W, CV_32SC1);
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& rows) {
    std::vector<int> candidates;
    std::vector<float> level;
    candidates.reserve(views.size());
    level.reserve(views.size());
    for (int v = rows.start; v < rows.end; ++v) {
      const auto* xy_row = xy_.ptr<cv::Vec2f>(v);
      const auto* J_row = jacobian_.ptr<cv::Vec4f>(v);
      float* out_row = out.ptr<float>(v);
      int* id_row = object_ids ? object_ids->ptr<int>(v) : nullptr;
      for (int u = 0; u < W; ++u) {
        const float xc = xy_row[u][0], yc = xy_row[u][1];
        const cv::Vec4f J = J_row[u];
        const float rx = 0.5f * (std::abs(J[0]) + std::abs(J[1])), ry = 0.5f * (std::abs(J[2]) + std::abs(J[3]));
        candidates.clear();
        for (std::size_t k = 0; k < views.size(); ++k) {
          const auto& pv = views[k];
          if (xc + rx >= pv.bx0 && xc - rx <= pv.bx1 && yc + ry >= pv.by0 && yc - ry <= pv.by1)
            candidates.push_back(static_cast<int>(k));
        }
        const std::size_t tile = static_cast<std::size_t>((v / kTile) * tiles_x_ + u / kTile);
        const std::uint32_t t_begin = tris.empty() ? 0 : tile_start[tile],
                            t_end = tris.empty() ? 0 : tile_start[tile + 1];
        // The sky is smooth: one value per pixel, along its centre's ray, computed when a sample misses.
        float sky_px = lighting.dome ? -1.0f : sky;
        const auto pixel_sky = [&] {
          if (sky_px < 0.0f) sky_px = static_cast<float>(sky_radiance(lighting, R_wc * Vec3(xc, yc, 1.0)));
          return sky_px;
        };
        if (candidates.empty() && t_begin == t_end) {
          out_row[u] = pixel_sky();
          if (id_row) id_row[u] = -1;
          continue;
        }
        level.assign(candidates.size(), -1.0f);
        float sum = 0.0f;
        int sample = 0;
        for (int sy = 0; sy < S; ++sy) {
          const float dv = (static_cast<float>(sy) + 0.5f) * inv_s - 0.5f;
          for (int sx = 0; sx < S; ++sx, ++sample) {
            const float du = (static_cast<float>(sx) + 0.5f) * inv_s - 0.5f;
            const float x = xc + J[0] * du + J[1] * dv, y = yc + J[2] * du + J[3] * dv;
            float best = std::numeric_limits<float>::infinity(), ba = 0, bb = 0, bez = 0, bex = 0, bey = 0;
            int bk = -1;
            for (std::size_t c = 0; c < candidates.size(); ++c) {
              const auto& pv = views[static_cast<std::size_t>(candidates[c])];
              const auto& R = pv.R;
              const float ez = R[6] * x + R[7] * y + R[8];
              const float lam = -pv.o[2] / ez;  // depth along the optical axis (the ray has z = 1)
              if (!(lam > 1e-3f) || !(lam < best)) continue;
              const float ex = R[0] * x + R[1] * y + R[2], ey = R[3] * x + R[4] * y + R[5];
              const float a = pv.o[0] + lam * ex, b = pv.o[1] + lam * ey;
              if (a < pv.min_a || a > pv.max_a || b < pv.min_b || b > pv.max_b) continue;
              best = lam, ba = a, bb = b, bk = static_cast<int>(c), bez = ez, bex = ex, bey = ey;
            }
            // Triangles of this tile: the same depth λ (z of the hit, the ray has z = 1).
            int bt = -1;
            float b0 = 0, b1 = 0, b2 = 0;
            for (std::uint32_t q = t_begin; q < t_end; ++q) {
              const TriangleView& tv = tris[tile_tris[q]];
              const auto& e = tv.e;
              const float e0 = e[0] * x + e[1] * y + e[2], e1 = e[3] * x + e[4] * y + e[5],
                          e2 = e[6] * x + e[7] * y + e[8];
              const float es = e0 + e1 + e2;
              // Inside (inclusive, so shared edges leave no cracks): every barycentric e_i/es ≥ 0.
              if (es == 0.0f || e0 * es < 0.0f || e1 * es < 0.0f || e2 * es < 0.0f) continue;
              const float lam = tv.V / es;
              if (!(lam > 1e-3f) || !(lam < best)) continue;
              best = lam, bt = static_cast<int>(tile_tris[q]);
              const float inv = 1.0f / es;
              b0 = e0 * inv, b1 = e1 * inv, b2 = e2 * inv;
            }
            if (bt >= 0) {
              const TriangleView& tv = tris[static_cast<std::size_t>(bt)];
              const MeshObject& obj = scene.meshes[static_cast<std::size_t>(tv.object)];
              const auto& n = tv.n;
              const Eigen::Vector3f nn(b0 * n[0] + b1 * n[3] + b2 * n[6], b0 * n[1] + b1 * n[4] + b2 * n[7],
                                       b0 * n[2] + b1 * n[5] + b2 * n[8]);
              const float len = nn.norm();
              const float cosine = len > 0.0f ? nn.dot(light) / len : 0.0f;
              float r = static_cast<float>(obj.albedo);
              if (obj.reflectance) {
                const auto& P = tv.p;
                const Vec3 p_obj(b0 * P[0] + b1 * P[3] + b2 * P[6], b0 * P[1] + b1 * P[4] + b2 * P[7],
                                 b0 * P[2] + b1 * P[5] + b2 * P[8]);
                r *= static_cast<float>(obj.reflectance(p_obj));
              }
              sum += r * (ambient + direct * std::max(0.0f, cosine));
              if (id_row && sample == centre_sample) id_row[u] = patch_count + tv.object;
              continue;
            }
            if (bk < 0) {
              sum += pixel_sky();
              if (id_row && sample == centre_sample) id_row[u] = -1;
              continue;
            }
            const auto& pv = views[static_cast<std::size_t>(candidates[static_cast<std::size_t>(bk)])];
            if (id_row && sample == centre_sample)
              id_row[u] = view_id[static_cast<std::size_t>(candidates[static_cast<std::size_t>(bk)])];
            const auto& A = pv.A;
            float& lev = level[static_cast<std::size_t>(bk)];
            if (lev < 0.0f) {
              // Texture footprint of one pixel: ∂ξ/∂(u,v) = A ∂(a,b)/∂(x,y) J, with
              // (a,b) = o + λ e, λ = −o_z/e_z, e = R (x, y, 1).
              const auto& R = pv.R;
              const float lam = best;
              const float dl_dx = -lam * R[6] / bez, dl_dy = -lam * R[7] / bez;
              const float da_dx = lam * R[0] + bex * dl_dx, da_dy = lam * R[1] + bex * dl_dy;
              const float db_dx = lam * R[3] + bey * dl_dx, db_dy = lam * R[4] + bey * dl_dy;
              const float det_ab = da_dx * db_dy - da_dy * db_dx;
              const float det = std::abs(det_ab * (J[0] * J[3] - J[1] * J[2]) * (A[0] * A[4] - A[1] * A[3]));
              // log2 of texels per sample: half the log2 of the area ratio, minus log2 S.
              lev = std::max(0.0f, 0.5f * std::log2(std::max(det, 1e-30f)) - log2_s);
            }
            const float tx = A[0] * ba + A[1] * bb + A[2], ty = A[3] * ba + A[4] * bb + A[5];
            sum += pv.shade * trilinear(*pv.texture, tx, ty, lev);
          }
        }
        out_row[u] = sum * inv_s * inv_s;
      }
    }
  });
  return out;
}

// --- optics and sensor -------------------------------------------------------------------

cv::Mat motion_blur(const cv::Mat& radiance, const camera::CameraIntrinsics& intrinsics, const Vec3& omega_camera,
                    double exposure_s) {
  // d/dt of the principal ray (0, 0, 1) seen from a camera turning at ω: −ω × e_z = (−ω_y, ω_x, 0).
  const double fu = -intrinsics.fx * omega_camera.y() * exposure_s;
  const double fv = intrinsics.fy * omega_camera.x() * exposure_s;
  const double length = std::hypot(fu, fv);
  if (!(length >= 0.05)) return radiance;
  const int half = static_cast<int>(std::ceil(0.5 * length)) + 1;
  cv::Mat kernel = cv::Mat::zeros(2 * half + 1, 2 * half + 1, CV_32F);
  // Splat points evenly spaced along the centred segment, bilinearly, so the kernel is the
  // anti-aliased line and point-symmetric about its centre.
  const int n = std::max(2, static_cast<int>(std::ceil(8.0 * length)) + 1);
  for (int i = 0; i < n; ++i) {
    const double s = static_cast<double>(i) / (n - 1) - 0.5;
    const double x = half + s * fu, y = half + s * fv;
    const int x0 = static_cast<int>(std::floor(x)), y0 = static_cast<int>(std::floor(y));
    const double ax = x - x0, ay = y - y0;
    kernel.at<float>(y0, x0) += static_cast<float>((1 - ax) * (1 - ay));
    kernel.at<float>(y0, x0 + 1) += static_cast<float>(ax * (1 - ay));
    kernel.at<float>(y0 + 1, x0) += static_cast<float>((1 - ax) * ay);
    kernel.at<float>(y0 + 1, x0 + 1) += static_cast<float>(ax * ay);
  }
  kernel /= cv::sum(kernel)[0];
  cv::Mat out;
  cv::filter2D(radiance, out, CV_32F, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REFLECT);
  return out;
}

cv::Mat sensor_image(const cv::Mat& radiance, const SensorModel& s, std::uint64_t noise_seed) {
  if (radiance.type() != CV_32FC1) throw std::invalid_argument("sensor_image: expected a CV_32FC1 radiance image");
  if (!(s.full_well_e > 0.0) || !(s.gain > 0.0) || !(s.gamma > 0.0) || !(s.noise_scale >= 0.0) ||
      !(s.blur_sigma_px >= 0.0))
    throw std::invalid_argument("sensor_image: full well, gain and gamma must be positive, noise and blur >= 0");
  cv::Mat img;
  if (s.blur_sigma_px > 0.0)
    cv::GaussianBlur(radiance, img, cv::Size(0, 0), s.blur_sigma_px, s.blur_sigma_px, cv::BORDER_REFLECT);
  else
    img = radiance.clone();
  // Electrons collected.
  cv::Mat e;
  cv::max(img, 0.0, e);
  e *= s.gain * s.full_well_e;
  if (s.noise_scale > 0.0) {
    cv::Mat noise(e.size(), CV_32F), sigma;
    cv::RNG rng(noise_seed == 0 ? 0x2545f4914f6cdd1dULL : noise_seed);
    rng.fill(noise, cv::RNG::NORMAL, 0.0, 1.0);
    // Photon noise variance = signal (Poisson), read noise added in quadrature.
    const double k2 = s.noise_scale * s.noise_scale;
    cv::sqrt(e * k2 + k2 * s.read_noise_e * s.read_noise_e, sigma);
    e += noise.mul(sigma);
  }
  cv::Mat linear;
  cv::min(cv::max(e * (1.0 / s.full_well_e), 0.0), 1.0, linear);
  cv::Mat encoded;
  cv::pow(linear, 1.0 / s.gamma, encoded);
  cv::Mat out;
  encoded.convertTo(out, CV_8U, 255.0);
  return out;
}

std::string encode_jpeg(const cv::Mat& image, int quality) {
  if (quality < 1 || quality > 100)
    throw std::invalid_argument(fmt::format("JPEG quality {} is outside 1..100", quality));
  std::vector<uchar> buffer;
  if (!cv::imencode(".jpg", image, buffer, {cv::IMWRITE_JPEG_QUALITY, quality}))
    throw std::runtime_error("cv::imencode failed to encode a JPEG");
  return {buffer.begin(), buffer.end()};
}

}  // namespace antpose::sim
