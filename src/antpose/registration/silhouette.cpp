#include "antpose/registration/silhouette.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <tuple>

#include <fmt/format.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/camera/edge_search.hpp"
#include "antpose/core/statistics.hpp"

namespace antpose::registration {
namespace {

using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;

// The mesh welded by position (files and parametric panels may repeat vertices along creases),
// with each edge's two triangles: contour generators are edges whose triangles face opposite ways.
struct EdgeMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<Vec3> normals;  // by winding, not normalised
  struct Edge {
    std::uint32_t a, b;
    std::vector<std::uint32_t> faces;
  };
  std::vector<Edge> edges;
  bool closed = false;  // every edge between two triangles or more: the mesh bounds a solid
};

EdgeMesh weld(const model::Mesh& mesh) {
  EdgeMesh m;
  std::map<std::tuple<long long, long long, long long>, std::uint32_t> index;
  std::vector<std::uint32_t> remap(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& v = mesh.vertices[i];
    const auto key = std::make_tuple(std::llround(v.x() * 1e7), std::llround(v.y() * 1e7), std::llround(v.z() * 1e7));
    const auto [it, inserted] = index.emplace(key, static_cast<std::uint32_t>(m.vertices.size()));
    if (inserted) m.vertices.push_back(v);
    remap[i] = it->second;
  }
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> edge_index;
  for (const auto& t : mesh.triangles) {
    const std::array<std::uint32_t, 3> w{remap.at(t[0]), remap.at(t[1]), remap.at(t[2])};
    if (w[0] == w[1] || w[1] == w[2] || w[0] == w[2]) continue;
    const auto f = static_cast<std::uint32_t>(m.triangles.size());
    m.triangles.push_back(w);
    m.normals.push_back((m.vertices[w[1]] - m.vertices[w[0]]).cross(m.vertices[w[2]] - m.vertices[w[0]]));
    for (int k = 0; k < 3; ++k) {
      const auto key = std::minmax(w[k], w[(k + 1) % 3]);
      const auto [it, inserted] = edge_index.emplace(key, m.edges.size());
      if (inserted) m.edges.push_back({key.first, key.second, {}});
      m.edges[it->second].faces.push_back(f);
    }
  }
  m.closed = std::all_of(m.edges.begin(), m.edges.end(), [](const EdgeMesh::Edge& e) { return e.faces.size() >= 2; });
  return m;
}

struct Pose {
  Mat3 R = Mat3::Identity();  // R_board_antenna
  Vec3 t = Vec3::Zero();      // p_board_antenna
  Iso3 T() const {
    Iso3 T_board_antenna = Iso3::Identity();
    T_board_antenna.linear() = R;
    T_board_antenna.translation() = t;
    return T_board_antenna;
  }
};

// One photo cropped around the antenna: gradient images of a Gaussian pyramid.
struct PreparedView {
  bool usable = false;
  Mat3 R_cb = Mat3::Identity();
  Vec3 t_cb = Vec3::Zero();
  Vec2 offset = Vec2::Zero();  // crop origin, full-resolution px
  cv::Size size;
  std::vector<cv::Mat> gx, gy;  // CV_32F per level, 0 where masked
  // Per level (empty without occluders or background edges): 255 where the antenna's outline
  // cannot be seen — on a nearer object, on a known object's edge, or within the edge's blur.
  std::vector<cv::Mat> mask;
};

// std::lround (half away from zero) inline: the mask look-ups below run once per pixel step of
// every search line, where the libm call took 6 % of a measurement.
int round_px(double v) { return static_cast<int>(v < 0.0 ? v - 0.5 : v + 0.5); }

// Whether an outline point at `p` (full-resolution px) falls on the view's mask at `level`.
bool masked(const PreparedView& v, int level, const Vec2& p) {
  if (v.mask.empty()) return false;
  const Vec2 q = (p - v.offset) / std::ldexp(1.0, level);
  const int x = round_px(q.x()), y = round_px(q.y());
  const cv::Mat& m = v.mask[static_cast<std::size_t>(level)];
  return x >= 0 && y >= 0 && x < m.cols && y < m.rows && m.at<std::uint8_t>(y, x) != 0;
}

// The view's mask at one level: the occluders filled, the background edges drawn, both widened
// by `guard_px` (the level's px) so that their blurred edges cannot be taken for the antenna's.
cv::Mat level_mask(const SilhouetteView& in, const Vec2& offset, cv::Size size, int level, double guard_px) {
  cv::Mat m = cv::Mat::zeros(size, CV_8UC1);
  const double s = std::ldexp(1.0, -level);
  constexpr int kShift = 2;  // quarter-pixel vertices
  const auto to_level = [&](const std::vector<cv::Point2f>& poly) {
    std::vector<cv::Point> out;
    for (const auto& p : poly)
      out.emplace_back(static_cast<int>(std::lround((p.x - offset.x()) * s * (1 << kShift))),
                       static_cast<int>(std::lround((p.y - offset.y()) * s * (1 << kShift))));
    return out;
  };
  for (const auto& poly : in.occluders)
    if (poly.size() >= 3) cv::fillPoly(m, std::vector<std::vector<cv::Point>>{to_level(poly)}, 255, cv::LINE_8, kShift);
  for (const auto& line : in.background_edges)
    if (line.size() >= 2)
      cv::polylines(m, std::vector<std::vector<cv::Point>>{to_level(line)}, false, 255, 1, cv::LINE_8, kShift);
  const int r = static_cast<int>(std::ceil(guard_px));
  cv::dilate(m, m, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1)));
  return m;
}

struct Sample {
  Vec2 normal;                    // outward, image
  double r = 0;                   // measured edge − projection along the normal, full-resolution px
  Eigen::Matrix<double, 1, 6> J;  // d(projection · normal)/d(δ, δt)
  std::uint32_t edge = 0;         // the mesh edge it lies on (correlated errors, see covariance)
  double px_per_m = 0;            // f / depth: image size of a model shape error
};

std::optional<Vec2> project(const camera::CameraIntrinsics& K, const PreparedView& v, const Vec3& p_board) {
  const Vec3 c = v.R_cb * p_board + v.t_cb;
  if (c.z() <= 1e-3) return std::nullopt;
  return K.project(c);
}

// Bounding box (full-resolution px) of the projected vertices; nullopt when one is behind the camera.
std::optional<cv::Rect2d> projected_box(const camera::CameraIntrinsics& K, const PreparedView& v, const EdgeMesh& m,
                                        const Pose& pose) {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const auto& p : m.vertices) {
    const auto uv = project(K, v, pose.R * p + pose.t);
    if (!uv) return std::nullopt;
    x0 = std::min(x0, uv->x()), y0 = std::min(y0, uv->y()), x1 = std::max(x1, uv->x()), y1 = std::max(y1, uv->y());
  }
  return cv::Rect2d(x0, y0, x1 - x0, y1 - y0);
}

// Outline points of one view, counted: those on the model's box (candidates, of which some fall
// outside the crop) and those on its attachments (options.outline_box_m), whose edge costs (as in
// score()) are summed but which are not samples of the fit.
struct OutlineCounts {
  std::size_t candidates = 0, outside = 0, attachment_candidates = 0;
  double attachment_cost = 0;
  bool reached_middle = false;  // some search line behind the outline reached the projection's middle
  OutlineCounts& operator+=(const OutlineCounts& c) {
    candidates += c.candidates, outside += c.outside, attachment_candidates += c.attachment_candidates;
    attachment_cost += c.attachment_cost;
    reached_middle = reached_middle || c.reached_middle;
    return *this;
  }
};

// A sample's cost in score(): its squared distance truncated at score_cutoff_px, 1 without an edge.
double edge_cost(std::optional<double> r_px, const SilhouetteOptions& o) {
  return r_px ? std::min(1.0, (*r_px * *r_px) / (o.score_cutoff_px * o.score_cutoff_px)) : 1.0;
}

// The model's projection in one photo as a mask (for a closed mesh its front faces alone cover it:
// every line of sight into the solid enters through one), edges subdivided so that the
// distortion's bowing is kept; over the projection's own box (so that the outer-contour test also
// works outside the crop, where samples are counted as unmeasurable), at most ~1000 px. With the
// vertices' projections; nullopt where part of the model is behind the camera.
struct ProjectionMask {
  cv::Mat mask;
  Vec2 origin = Vec2::Zero();
  double ms = 1.0;  // image px per mask px
  std::vector<std::optional<Vec2>> uv;

  Vec2 to_mask(const Vec2& p) const { return Vec2((p.x() - origin.x()) / ms, (p.y() - origin.y()) / ms); }
  bool inside(const Vec2& q) const {
    const int x = round_px(q.x()), y = round_px(q.y());
    return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<std::uint8_t>(y, x) != 0;
  }
};

std::optional<ProjectionMask> project_model(const EdgeMesh& m, const Pose& pose, const PreparedView& v,
                                            const camera::CameraIntrinsics& K, const std::vector<char>& front) {
  ProjectionMask out;
  out.uv.resize(m.vertices.size());
  Vec2 lo = Vec2::Constant(1e300), hi = Vec2::Constant(-1e300);
  for (std::size_t i = 0; i < m.vertices.size(); ++i) {
    out.uv[i] = project(K, v, pose.R * m.vertices[i] + pose.t);
    if (!out.uv[i]) return std::nullopt;
    lo = lo.cwiseMin(*out.uv[i]), hi = hi.cwiseMax(*out.uv[i]);
  }
  const double pad = 8 + 0.05 * (hi - lo).maxCoeff();
  out.origin = lo - Vec2::Constant(pad);
  const Vec2 extent = hi - lo + Vec2::Constant(2 * pad);
  if (!(extent.maxCoeff() < 1e5)) return std::nullopt;  // a degenerate projection (model at the camera)
  out.ms = std::max(1.0, extent.maxCoeff() / 1000.0);
  out.mask = cv::Mat::zeros(static_cast<int>(std::ceil(extent.y() / out.ms)) + 1,
                            static_cast<int>(std::ceil(extent.x() / out.ms)) + 1, CV_8UC1);
  std::vector<cv::Point> poly;
  for (std::size_t f = 0; f < m.triangles.size(); ++f) {
    if (m.closed && !front[f]) continue;
    const auto& t = m.triangles[f];
    poly.clear();
    for (int k = 0; k < 3; ++k) {
      const Vec3 A = pose.R * m.vertices[t[k]] + pose.t, B = pose.R * m.vertices[t[(k + 1) % 3]] + pose.t;
      const double len = (*out.uv[t[(k + 1) % 3]] - *out.uv[t[k]]).norm() / out.ms;
      const int n = std::clamp(static_cast<int>(std::ceil(len / 8.0)), 1, 64);
      for (int j = 0; j < n; ++j) {
        const auto p = project(K, v, A + (B - A) * (double(j) / n));
        if (!p) return std::nullopt;
        const Vec2 q = out.to_mask(*p) * 4.0;  // shift = 2: quarter-pixel vertices
        poly.emplace_back(round_px(q.x()), round_px(q.y()));
      }
    }
    const cv::Point* vertices = poly.data();
    const int count = static_cast<int>(poly.size());
    cv::fillPoly(out.mask, &vertices, &count, 1, cv::Scalar(255), cv::LINE_8, 2);
  }
  return out;
}

// d(projection · normal)/d(δ, δt) of the point X (board frame) of the model at `pose`, by central
// differences in the camera frame (distortion included).
std::optional<Eigen::Matrix<double, 1, 6>> sample_jacobian(const camera::CameraIntrinsics& K, const PreparedView& v,
                                                           const Pose& pose, const Vec3& X, const Vec2& normal) {
  const Vec3 Xc = v.R_cb * X + v.t_cb;
  Eigen::Matrix<double, 2, 3> dp;
  const double h = 1e-6 * Xc.z();
  for (int a = 0; a < 3; ++a) {
    Vec3 dx = Vec3::Zero();
    dx[a] = h;
    const auto pp = K.project(Xc + dx), pm = K.project(Xc - dx);
    if (!pp || !pm) return std::nullopt;
    dp.col(a) = (*pp - *pm) / (2 * h);
  }
  Eigen::Matrix<double, 3, 6> dX;
  dX.leftCols<3>() = -skew(X - pose.t);
  dX.rightCols<3>() = Mat3::Identity();
  return Eigen::Matrix<double, 1, 6>(normal.transpose() * dp * v.R_cb * dX);
}

// The outer contour samples of one view at `level` with their edge measurements; the
// attachments' outline is measured only `with_attachments` (for score_with_attachments, once).
void gather(const EdgeMesh& m, const Pose& pose, const PreparedView& v, const camera::CameraIntrinsics& K, int level,
            double search_px, const SilhouetteOptions& o, bool with_attachments, std::vector<Sample>& out,
            OutlineCounts& counts) {
  counts = {};
  if (!v.usable) return;
  const double scale = std::ldexp(1.0, level);
  // Camera centre in the antenna frame decides which faces look at the camera.
  const Vec3 centre_board = -v.R_cb.transpose() * v.t_cb;
  const Vec3 centre_antenna = pose.R.transpose() * (centre_board - pose.t);
  std::vector<char> front(m.triangles.size());
  for (std::size_t f = 0; f < m.triangles.size(); ++f)
    front[f] = m.normals[f].dot(centre_antenna - m.vertices[m.triangles[f][0]]) > 0;
  const auto projection = project_model(m, pose, v, K, front);
  if (!projection) return;
  const ProjectionMask& pm = *projection;
  // The projection's extent behind an outline point (mask px against its outward normal), up to
  // twice the search range: beyond, it does not limit the search.
  const double max_depth = 2 * search_px * scale / pm.ms + 2;
  auto depth_inside = [&](const Vec2& q, const Vec2& outward) {
    double depth = 1;
    while (depth < max_depth && pm.inside(q - depth * outward)) depth += 1;
    return depth;
  };
  const Vec3 half_box = o.outline_box_m / 2 + Vec3::Constant(o.box_tolerance_m);
  const bool whole_outline = !(o.outline_box_m.array() > 0).all();
  auto on_box = [&](const Vec3& p_antenna) {
    return whole_outline || (p_antenna.cwiseAbs().array() <= half_box.array()).all();
  };
  std::vector<double> g;
  const double spacing = o.sample_spacing_px * scale;
  for (std::size_t ei = 0; ei < m.edges.size(); ++ei) {
    const auto& e = m.edges[ei];
    bool silhouette = e.faces.size() == 1;
    for (std::size_t i = 1; i < e.faces.size(); ++i) silhouette |= front[e.faces[i]] != front[e.faces[0]];
    if (!silhouette) continue;
    const Vec3& a_antenna = m.vertices[e.a];
    const Vec3& b_antenna = m.vertices[e.b];
    const int n = static_cast<int>(std::floor((*pm.uv[e.b] - *pm.uv[e.a]).norm() / spacing));
    const Vec3 A = pose.R * a_antenna + pose.t, B = pose.R * b_antenna + pose.t;
    for (int j = 0; j < n; ++j) {
      const double s = (j + 0.5) / n, ds = 0.25 / n;
      const bool attachment = !on_box(a_antenna + (b_antenna - a_antenna) * s);
      if (attachment && !with_attachments) continue;
      const Vec3 X = A + (B - A) * s;
      const auto p = project(K, v, X);
      const auto p0 = project(K, v, A + (B - A) * (s - ds));
      const auto p1 = project(K, v, A + (B - A) * (s + ds));
      if (!p || !p0 || !p1) continue;
      const Vec2 d = (*p1 - *p0).normalized();
      Vec2 normal(-d.y(), d.x());
      const Vec2 q = pm.to_mask(*p);
      const bool in_minus = pm.inside(q - 1.5 * normal), in_plus = pm.inside(q + 1.5 * normal);
      if (in_minus == in_plus) continue;  // inner edge, or hidden by another part of the model
      if (in_plus) normal = -normal;
      if (masked(v, level, *p)) continue;  // hidden, or where a known object's edge would be taken for it
      const Vec2 in_crop = *p - v.offset;
      const bool in_view =
          in_crop.x() >= 0 && in_crop.y() >= 0 && in_crop.x() <= v.size.width - 1 && in_crop.y() <= v.size.height - 1;
      if (attachment) {
        ++counts.attachment_candidates;
      } else {
        ++counts.candidates;
        if (!in_view) ++counts.outside;
      }
      if (!in_view) {
        if (attachment) counts.attachment_cost += edge_cost(std::nullopt, o);
        continue;
      }
      // 1-D search along the normal for the nearest strong edge (Drummond & Cipolla 2002); the
      // masked parts' gradients are 0, so a nearer object's edge is never taken. Behind the
      // outline the line ends at the projection's middle: beyond it lies the far side of the
      // model's own outline, and on a panel narrower than the search range that far side (against
      // the sky, say, where this side is against a grey mast) is often the stronger edge: taken
      // for this side's, or ranking this side's as too weak, it pulls the pose across the panel.
      // (Whether the middle is within reach is noted either way: where it never is, the descent
      // is the same with line_ends_at_middle on or off.)
      const double middle = 0.5 * depth_inside(q, normal) * pm.ms / scale;
      counts.reached_middle = counts.reached_middle || middle < search_px;
      const double behind = o.line_ends_at_middle ? std::min(search_px, middle) : search_px;
      const auto edge = camera::nearest_edge(v.gx[level], v.gy[level], in_crop / scale, normal, {behind, search_px},
                                             o.min_edge_gradient, g);
      if (attachment) {
        counts.attachment_cost += edge_cost(edge ? std::optional<double>(*edge * scale) : std::nullopt, o);
        continue;
      }
      if (!edge) continue;
      const auto J = sample_jacobian(K, v, pose, X, normal);
      if (!J) continue;
      const double depth = (v.R_cb * X + v.t_cb).z();
      out.push_back({normal, *edge * scale, *J, static_cast<std::uint32_t>(ei), 0.5 * (K.fx + K.fy) / depth});
    }
  }
}

struct Gathered {
  std::vector<std::vector<Sample>> per_view;
  std::vector<OutlineCounts> per_view_counts;
  OutlineCounts counts;
  std::size_t views_with_samples = 0;
};

Gathered gather_all(const EdgeMesh& m, const Pose& pose, const std::vector<PreparedView>& views,
                    const camera::CameraIntrinsics& K, int level, double search_px, const SilhouetteOptions& o,
                    bool with_attachments = false) {
  Gathered g;
  g.per_view.resize(views.size());
  auto& counts = g.per_view_counts;
  counts.resize(views.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(views.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i)
      gather(m, pose, views[i], K, level, search_px, o, with_attachments, g.per_view[i], counts[i]);
  });
  for (std::size_t i = 0; i < views.size(); ++i) {
    g.counts += counts[i];
    g.views_with_samples += g.per_view[i].empty() ? 0 : 1;
  }
  return g;
}

// The photos prepared for the outline of the model at `pose`: each cropped (its ROI, or the
// model's projected box plus a margin), as gradient pyramids in linear intensity (edges are
// located there: in encoded values the outline's width, and so the yaw, would be biased), masked
// where known objects are. `top`: the coarsest level, where the model's narrowest projection is
// still min_coarse_width_px wide (at most `max_level`).
struct PreparedViews {
  std::vector<PreparedView> views;
  int top = 0;
};

PreparedViews prepare_views(const EdgeMesh& m, const Pose& pose, const std::vector<SilhouetteView>& views,
                            const camera::CameraIntrinsics& intrinsics, const SilhouetteOptions& options, int max_level,
                            std::vector<std::string>& warnings) {
  PreparedViews out;
  auto& prepared = out.views;
  prepared.resize(views.size());
  double narrowest = 1e300;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const auto& in = views[i];
    if (in.image.type() != CV_8UC1 || in.image.cols != intrinsics.width || in.image.rows != intrinsics.height)
      throw std::invalid_argument(fmt::format("refine_by_silhouette: view {} is not a CV_8UC1 image of {}x{} px", i,
                                              intrinsics.width, intrinsics.height));
    auto& v = prepared[i];
    v.R_cb = in.R_camera_board;
    v.t_cb = in.t_camera_board;
    const auto box = projected_box(intrinsics, v, m, pose);
    if (!box) {
      warnings.push_back(fmt::format("view {}: the model lies (partly) behind the camera; skipped", i));
      continue;
    }
    cv::Rect crop;
    if (in.roi) {
      crop = *in.roi;
    } else {
      const double margin = options.roi_margin_px + 0.1 * std::max(box->width, box->height);
      crop = cv::Rect(static_cast<int>(std::floor(box->x - margin)), static_cast<int>(std::floor(box->y - margin)),
                      static_cast<int>(std::ceil(box->width + 2 * margin)),
                      static_cast<int>(std::ceil(box->height + 2 * margin)));
    }
    crop &= cv::Rect(0, 0, in.image.cols, in.image.rows);
    if (crop.width < 16 || crop.height < 16) {
      warnings.push_back(fmt::format("view {}: the antenna's region lies outside the photo; skipped", i));
      continue;
    }
    v.usable = true;
    v.offset = Vec2(crop.x, crop.y);
    v.size = crop.size();
    narrowest = std::min(narrowest, std::min(box->width, box->height));
  }
  if (narrowest < 1e300)
    out.top =
        std::clamp(static_cast<int>(std::floor(std::log2(std::max(1.0, narrowest / options.min_coarse_width_px)))), 0,
                   std::max(0, max_level));
  cv::parallel_for_(cv::Range(0, static_cast<int>(views.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) {
      auto& v = prepared[i];
      if (!v.usable) continue;
      const cv::Mat crop = views[i].image(
          cv::Rect(static_cast<int>(v.offset.x()), static_cast<int>(v.offset.y()), v.size.width, v.size.height));
      cv::Mat level = camera::linear_intensity(crop, options.gamma);
      const bool with_mask = !views[i].occluders.empty() || !views[i].background_edges.empty();
      for (int l = 0; l <= out.top; ++l) {
        if (l > 0) {
          cv::Mat down;
          cv::pyrDown(level, down);
          level = down;
        }
        auto [gx, gy] = camera::smoothed_gradients(level, options.smoothing_sigma_px);
        if (with_mask) {
          v.mask.push_back(level_mask(views[i], v.offset, level.size(), l, options.mask_guard_px));
          gx.setTo(0, v.mask.back());
          gy.setTo(0, v.mask.back());
        }
        v.gx.push_back(gx);
        v.gy.push_back(gy);
      }
    }
  });
  return out;
}

// Tukey weights with the scale from the median absolute residual (in the level's px).
struct Normal {
  Mat6 H = Mat6::Zero();
  Vec6 b = Vec6::Zero();
  double sum_w = 0, sum_wr2 = 0;
  std::size_t inliers = 0, samples = 0;
  double c = 0;  // Tukey's cut-off, full-resolution px
  double weight(double r) const {
    if (!(std::abs(r) < c)) return 0.0;
    const double u = r / c;
    return (1 - u * u) * (1 - u * u);
  }
};

Normal normal_equations(const Gathered& g, double scale, const SilhouetteOptions& o) {
  Normal n;
  std::vector<double> abs_r;
  for (const auto& v : g.per_view)
    for (const auto& s : v) abs_r.push_back(std::abs(s.r) / scale);
  n.samples = abs_r.size();
  if (abs_r.empty()) return n;
  const double sigma = std::max(0.5, 1.4826 * median(std::move(abs_r)));
  n.c = o.tukey_c * sigma * scale;
  for (const auto& v : g.per_view)
    for (const auto& s : v) {
      const double w = n.weight(s.r);
      if (w <= 0) continue;
      n.H += w * s.J.transpose() * s.J;
      n.b += w * s.J.transpose() * s.r;
      n.sum_w += w;
      n.sum_wr2 += w * s.r * s.r;
      ++n.inliers;
    }
  return n;
}

// Solves the damped normal equations over the free DOF; nullopt when they are singular.
std::optional<Vec6> solve(const Normal& n, const std::array<bool, 6>& free, Mat6* inverse = nullptr) {
  std::vector<int> idx;
  for (int i = 0; i < 6; ++i)
    if (free[i]) idx.push_back(i);
  const int k = static_cast<int>(idx.size());
  Eigen::MatrixXd H(k, k);
  Eigen::VectorXd b(k);
  for (int i = 0; i < k; ++i) {
    b[i] = n.b[idx[i]];
    for (int j = 0; j < k; ++j) H(i, j) = n.H(idx[i], idx[j]);
  }
  Eigen::LDLT<Eigen::MatrixXd> ldlt(H);
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 1e-12 * std::max(1.0, H.diagonal().maxCoeff())))
    return std::nullopt;
  Eigen::MatrixXd Hd = H;
  Hd.diagonal() *= 1.0 + 1e-6;  // a touch of Levenberg–Marquardt damping
  const Eigen::VectorXd x = Hd.ldlt().solve(b);
  Vec6 delta = Vec6::Zero();
  for (int i = 0; i < k; ++i) delta[idx[i]] = x[i];
  if (inverse) {
    const Eigen::MatrixXd Hi = ldlt.solve(Eigen::MatrixXd::Identity(k, k));
    inverse->setZero();
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k; ++j) (*inverse)(idx[i], idx[j]) = Hi(i, j);
  }
  if (!delta.allFinite()) return std::nullopt;
  return delta;
}

// Mean truncated quadratic cost of the outline at full resolution, in [0, 1]: 0 when every
// contour sample lies on an edge, 1 per sample without an edge within score_cutoff_px (fixed, so
// that poses compare; chamfer-like, Barrow et al. 1977). The box's outline, or with
// `with_attachments` the whole outline.
double score(const Gathered& g, const SilhouetteOptions& o, bool with_attachments = false) {
  const OutlineCounts& c = g.counts;
  const std::size_t candidates = c.candidates + (with_attachments ? c.attachment_candidates : 0);
  if (candidates == 0) return 1.0;
  double sum = with_attachments ? c.attachment_cost : 0.0;
  std::size_t found = 0;
  for (const auto& v : g.per_view)
    for (const auto& s : v) {
      sum += edge_cost(s.r, o);
      ++found;
    }
  return (sum + double(c.candidates - found)) / double(candidates);
}

// Adds the rotation prior to the normal equations as a measurement of the edges' units: its
// information × the edges' residual variance × the correlation inflation (so that it weighs as a
// Gaussian of its own covariance would against theirs). Returns that factor (0 without a prior).
double add_prior(Normal& n, const Mat3& R_board_antenna, const std::optional<RotationPrior>& prior,
                 const SilhouetteOptions& o) {
  if (!prior || n.sum_w <= 0) return 0.0;
  const double sigma2 = std::max(n.sum_wr2 / n.sum_w, 0.25 * 0.25);
  const double weight = sigma2 * std::max(1.0, o.correlation_length_px / o.sample_spacing_px);
  const Vec3 r = log_so3(prior->R_board_antenna * R_board_antenna.transpose());
  n.H.topLeftCorner<3, 3>() += weight * prior->information;
  n.b.head<3>() += weight * prior->information * r;
  return weight;
}

struct Descent {
  Pose pose;
  bool converged = false;
  int iterations = 0;
  double score = 1.0;
};

// The descents of one refinement: its prepared photos, stages (level, search in that level's px:
// the coarsest searches wide, every later one ±fine_search_px; a monotone descent also ends on a
// fine stage where the model is too narrow for a pyramid, on the edges the score and the
// covariance use — a narrow panel's own, not the mast's 20 px beyond it) and options.
class Descender {
 public:
  Descender(const EdgeMesh& m, const PreparedViews& ready, const camera::CameraIntrinsics& K,
            const SilhouetteOptions& o, const std::optional<RotationPrior>& prior)
      : m_(m), views_(ready.views), K_(K), o_(o), prior_(prior) {
    for (int level = ready.top; level >= 0; --level)
      stages_.emplace_back(level, level == ready.top
                                      ? std::max(o.fine_search_px, o.search_range_px / std::ldexp(1.0, level))
                                      : o.fine_search_px);
    if (monotone() && stages_.back().second > o.fine_search_px) stages_.emplace_back(0, o.fine_search_px);
  }

  Gathered gather(const Pose& p, int level, double search_px, bool with_attachments = false) {
    Gathered g = gather_all(m_, p, views_, K_, level, search_px, o_, with_attachments);
    reached_middle_ = reached_middle_ || g.counts.reached_middle;
    return g;
  }
  double full_score(const Pose& p) { return score(gather(p, 0, o_.fine_search_px), o_); }
  bool reached_middle() const { return reached_middle_; }

  Descent descend(const Pose& start) {
    Descent d;
    d.pose = start;
    for (const auto& [level, search] : stages_) descend_stage(d, level, search);
    d.score = full_score(d.pose);
    return d;
  }

 private:
  bool monotone() const { return o_.max_step_halvings >= 0; }

  void descend_stage(Descent& d, int level, double search) {
    const double scale = std::ldexp(1.0, level);
    // Monotone at full resolution: Gauss–Newton re-associates the edges at every step, and nearer
    // a strong clutter edge than the panel's own it walks off the outline while each step looks
    // good to its own linearisation; the score (which ranks the starts) does not.
    const bool checked = monotone() && level == 0;
    double current = checked ? full_score(d.pose) : 0.0;
    d.converged = false;
    Vec6 previous_step = Vec6::Zero();
    for (int it = 0; it < o_.max_iterations_per_level; ++it) {
      const Gathered g = gather(d.pose, level, search);
      Normal n = normal_equations(g, scale, o_);
      if (n.inliers < 12) break;
      add_prior(n, d.pose.R, prior_, o_);
      auto delta = solve(n, o_.free);
      if (!delta) break;
      ++d.iterations;
      // The step's weighted RMS image motion, in the level's px.
      const double motion = std::sqrt(std::max(0.0, delta->dot(n.H * *delta)) / n.sum_w) / scale;
      // A trust region on the rotation: where the outline hardly fixes the yaw (a narrow panel on
      // a coarse level, seen face-on from below) the step about the long axis can be 100°+, far
      // beyond the linearisation, and the descent wanders from basin to basin.
      if (const double turn = delta->head<3>().norm(); turn > o_.max_step_rotation_rad)
        *delta *= o_.max_step_rotation_rad / turn;
      // Where the outline hardly fixes a direction (the yaw of a narrow panel seen face-on),
      // samples entering and leaving the robust weights make the steps swing back and forth about
      // the minimum without shrinking: a small step reversing the last one has arrived, and half
      // of it lands between the two poses.
      const bool swinging = motion < o_.swing_motion_px && delta->dot(n.H * previous_step) < 0.0;
      if (swinging) *delta /= 2;
      if (checked && !lowers_score(d, *delta, current)) {  // nothing along Gauss–Newton's direction does: arrived
        d.converged = true;
        return;
      }
      d.pose.R = exp_so3(delta->head<3>()) * d.pose.R;
      d.pose.t += delta->tail<3>();
      previous_step = *delta;
      if (motion < 0.01 || swinging) {
        d.converged = true;
        return;
      }
    }
  }

  // The step, halved up to max_step_halvings times until it lowers the score (a line search).
  bool lowers_score(const Descent& d, Vec6& delta, double& current) {
    for (int halving = 0; halving <= o_.max_step_halvings; ++halving) {
      const double trial = full_score(Pose{exp_so3(delta.head<3>()) * d.pose.R, d.pose.t + delta.tail<3>()});
      if (trial <= current) {
        current = trial;
        return true;
      }
      delta /= 2;
    }
    return false;
  }

  const EdgeMesh& m_;
  const std::vector<PreparedView>& views_;
  const camera::CameraIntrinsics& K_;
  const SilhouetteOptions& o_;
  const std::optional<RotationPrior>& prior_;
  std::vector<std::pair<int, double>> stages_;
  bool reached_middle_ = false;  // by any search line of any evaluation
};

// The covariance at the solution (file comment): the sandwich H⁻¹ (Σ_white + Σ_bias) H⁻¹ of white
// edge noise (inflated for the samples' overlap), errors shared by all samples of a mesh edge (the
// model's shape tolerance, the same in every view; an edge-localisation bias per view and edge:
// background, blur, shading) and that bias common to the whole outline (a dilation). The prior
// counts once as information (in H) and once as its own noise (in M).
void covariance_at(SilhouetteResult& result, const Gathered& g, const Normal& n, const Mat6& Hinv, double prior_weight,
                   const std::optional<RotationPrior>& prior, const EdgeMesh& m, const Pose& pose,
                   const SilhouetteOptions& o) {
  result.rms_px = std::sqrt(n.sum_wr2 / n.sum_w);
  const double sigma2 = n.sum_wr2 / std::max(1.0, n.sum_w - 6.0);
  const double inflation = std::max(1.0, o.correlation_length_px / o.sample_spacing_px);
  Mat6 M = sigma2 * inflation * n.H;
  if (prior)
    M.topLeftCorner<3, 3>() += (prior_weight * prior_weight - sigma2 * inflation * prior_weight) * prior->information;
  std::vector<Vec6> shape(m.edges.size(), Vec6::Zero()), bias(m.edges.size(), Vec6::Zero());
  Vec6 dilation = Vec6::Zero();
  for (const auto& view : g.per_view)
    for (const auto& s : view) {
      const double w = n.weight(s.r);
      if (w <= 0) continue;
      shape[s.edge] += w * s.px_per_m * o.shape_tolerance_m * s.J.transpose();
      bias[s.edge] += w * o.edge_bias_px * s.J.transpose();
      dilation += w * o.outline_dilation_px * s.J.transpose();
    }
  for (std::size_t e = 0; e < m.edges.size(); ++e) M += shape[e] * shape[e].transpose() + bias[e] * bias[e].transpose();
  M += dilation * dilation.transpose();
  result.covariance = Hinv * M * Hinv;
  result.dilation_yaw_sigma_rad = std::abs((Hinv * dilation).head<3>().dot(pose.R.col(2)));
}

// The checks of the result (SilhouetteOptions' acceptance), each failure a warning; whether it
// passed them all but the iteration limit, which is judged last: alone, it leaves a descent a
// search may continue.
bool passes_checks(SilhouetteResult& result, bool solvable, const OutlineCounts& counts, const Descent& best,
                   const std::optional<Descent>& rival, const Pose& start, const SilhouetteOptions& o) {
  bool ok = solvable;
  auto fail = [&](std::string why) { ok = false, result.warnings.push_back(std::move(why)); };
  if (!solvable)
    result.warnings.push_back("silhouette: too few contour samples found an edge to fix the pose");
  else if (!best.converged)
    result.warnings.push_back(
        fmt::format("silhouette: no convergence within {} iterations at full resolution", o.max_iterations_per_level));
  const double outside = counts.candidates ? double(counts.outside) / double(counts.candidates) : 0.0;
  if (outside > o.max_outside_fraction)
    fail(
        fmt::format("silhouette: {:.0f} % of the model's outline falls outside the photos or their regions of interest",
                    100 * outside));
  if (static_cast<int>(result.views_used) < o.min_views)
    fail(fmt::format("silhouette: only {} view(s) show the model's outline (at least {} needed)", result.views_used,
                     o.min_views));
  if (result.inlier_fraction < o.min_inlier_fraction)
    fail(
        fmt::format("silhouette: only {:.0f} % of the model's outline meets an image edge (at least {:.0f} % "
                    "expected); is the antenna in the photos and the start close?",
                    100 * result.inlier_fraction, 100 * o.min_inlier_fraction));
  if (solvable && result.rms_px > o.max_rms_px)
    fail(fmt::format("silhouette: edge RMS {:.2f} px (more than {:.2f} px)", result.rms_px, o.max_rms_px));
  if (rival && rival->score < best.score) {
    result.left_start = rival->pose.T();
    fail(
        fmt::format("silhouette: a pose turned {:.1f}° from the result fits the outline better (score {:.3f} vs "
                    "{:.3f}) but lies more than {:.0f}° from the start: the start is probably wrong",
                    rad2deg(result.rival_rotation_rad), rival->score, best.score, rad2deg(o.max_rotation_change_rad)));
  } else if (rival && rival->score < best.score + o.rival_margin) {
    fail(
        fmt::format("silhouette: ambiguous yaw: a pose turned {:.1f}° fits the outline nearly as well (score {:.3f} "
                    "vs {:.3f}); photograph the antenna over a wider arc",
                    rad2deg(result.rival_rotation_rad), rival->score, best.score));
  }
  if (const double turned = rotation_distance(start.R, best.pose.R); turned > o.max_rotation_change_rad) {
    if (!result.left_start) result.left_start = result.T_board_antenna;
    fail(
        fmt::format("silhouette: the pose turned {:.1f}° from the start (more than {:.1f}°): probably another local "
                    "minimum",
                    rad2deg(turned), rad2deg(o.max_rotation_change_rad)));
  }
  return ok;
}

}  // namespace

SilhouetteResult refine_by_silhouette(const model::Mesh& mesh_antenna, const Iso3& T_board_antenna_initial,
                                      const std::vector<SilhouetteView>& views,
                                      const camera::CameraIntrinsics& intrinsics, const SilhouetteOptions& options,
                                      const std::optional<RotationPrior>& prior) {
  if (mesh_antenna.triangles.empty()) throw std::invalid_argument("refine_by_silhouette: the mesh has no triangles");
  const EdgeMesh m = weld(mesh_antenna);
  SilhouetteResult result;
  result.T_board_antenna = T_board_antenna_initial;
  const Pose start{T_board_antenna_initial.linear(), T_board_antenna_initial.translation()};
  const PreparedViews ready = prepare_views(m, start, views, intrinsics, options, options.max_level, result.warnings);
  Descender descender(m, ready, intrinsics, options, prior);

  Descent best = descender.descend(start);
  result.iterations = best.iterations;
  // A panel's outline is nearly the same at two yaws (the width w|cos θ| + d|sin θ| repeats
  // about θ = atan(d/w)) when the views span little: descend again from starts turned about the
  // long axis and keep the best score; a distinct rival that scores nearly as well is reported.
  std::optional<Descent> rival;
  for (const double offset : options.rival_yaw_offsets_rad) {
    Descent d = descender.descend(Pose{exp_so3(offset * best.pose.R.col(2)) * best.pose.R, best.pose.t});
    result.iterations += d.iterations;
    if (rotation_distance(d.pose.R, best.pose.R) < deg2rad(2.0)) continue;
    if (d.score < best.score && rotation_distance(d.pose.R, start.R) <= options.max_rotation_change_rad)
      std::swap(d, best);
    if (!rival || d.score < rival->score) rival = d;
  }
  result.score = best.score;
  if (rival) {
    result.rival_score = rival->score;
    result.rival_rotation_rad = rotation_distance(rival->pose.R, best.pose.R);
  }

  // Statistics and covariance at the solution (full resolution, fine search).
  const Gathered g = descender.gather(best.pose, 0, options.fine_search_px, true);
  result.search_reached_middle = descender.reached_middle();
  result.score_with_attachments = score(g, options, true);
  Normal n = normal_equations(g, 1.0, options);
  const double prior_weight = n.inliers > 12 ? add_prior(n, best.pose.R, prior, options) : 0.0;
  result.T_board_antenna = best.pose.T();
  result.views_used = g.views_with_samples;
  result.samples = n.inliers;
  result.inlier_fraction = g.counts.candidates ? double(n.inliers) / double(g.counts.candidates) : 0.0;
  Mat6 Hinv;
  const bool solvable = n.inliers > 12 && solve(n, options.free, &Hinv).has_value();
  if (solvable) covariance_at(result, g, n, Hinv, prior_weight, prior, m, best.pose, options);
  const bool ok = passes_checks(result, solvable, g.counts, best, rival, start, options);
  result.stopped_at_iteration_limit = ok && !best.converged;
  result.converged = ok && best.converged;
  return result;
}

OutlineEvaluation evaluate_outline(const model::Mesh& mesh_antenna, const Iso3& T_board_antenna,
                                   const std::vector<SilhouetteView>& views, const camera::CameraIntrinsics& intrinsics,
                                   const SilhouetteOptions& options) {
  if (mesh_antenna.triangles.empty()) throw std::invalid_argument("evaluate_outline: the mesh has no triangles");
  const EdgeMesh m = weld(mesh_antenna);
  const Pose pose{T_board_antenna.linear(), T_board_antenna.translation()};
  OutlineEvaluation out;
  std::vector<std::string> warnings;
  const PreparedViews ready = prepare_views(m, pose, views, intrinsics, options, 0, warnings);
  const Gathered g = gather_all(m, pose, ready.views, intrinsics, 0, options.fine_search_px, options);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t i = 0; i < views.size(); ++i) {
    const OutlineCounts& c = g.per_view_counts[i];
    double sum = 0.0;
    for (const auto& smp : g.per_view[i]) sum += edge_cost(smp.r, options);
    const double unfound = static_cast<double>(c.candidates - g.per_view[i].size());
    out.cost.push_back(c.candidates ? (sum + unfound) / static_cast<double>(c.candidates) : nan);
    out.samples.push_back(c.candidates);
  }
  out.score = score(g, options);
  return out;
}

}  // namespace antpose::registration
