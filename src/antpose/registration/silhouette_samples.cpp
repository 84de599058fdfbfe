#include "antpose/registration/silhouette_detail.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/camera/edge_search.hpp"
#include "antpose/core/rounding.hpp"
#include "antpose/registration/known_object_masks.hpp"

namespace antpose::registration::detail {

namespace {

// Whether an outline point at `p` (full-resolution px) falls on the view's mask at `level`.
bool masked(const PreparedView& v, int level, const Vec2& p) {
  if (v.mask.empty()) return false;
  const Vec2 q = (p - v.offset) / std::ldexp(1.0, level);
  const int x = round_half_away(q.x()), y = round_half_away(q.y());
  const cv::Mat& m = v.mask[static_cast<std::size_t>(level)];
  return x >= 0 && y >= 0 && x < m.cols && y < m.rows && m.at<std::uint8_t>(y, x) != 0;
}

std::optional<Vec2> project(const camera::CameraIntrinsics& K, const PreparedView& v, const Vec3& p_board) {
  const Vec3 c = v.R_cb * p_board + v.t_cb;
  if (c.z() <= 1e-3) return std::nullopt;
  return K.project(c);
}

// The same, with d(pixel)/d(camera-frame point).
std::optional<Vec2> project(const camera::CameraIntrinsics& K, const PreparedView& v, const Vec3& p_board,
                            Eigen::Matrix<double, 2, 3>& d_uv_d_camera) {
  const Vec3 c = v.R_cb * p_board + v.t_cb;
  if (c.z() <= 1e-3) return std::nullopt;
  return K.project(c, d_uv_d_camera);
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

}  // namespace

double edge_cost(std::optional<double> r_px, const SilhouetteOptions& o) {
  return r_px ? std::min(1.0, (*r_px * *r_px) / (o.score_cutoff_px * o.score_cutoff_px)) : 1.0;
}

namespace {

// The model's projection in one photo as a mask (for a closed mesh its front faces alone cover it:
// every line of sight into the solid enters through one), edges subdivided so that the
// distortion's bowing is kept; over the projection's own box (so that the outer-contour test also
// works outside the crop, where samples are counted as unmeasurable), at most ~1000 px and no finer
// than half the pyramid level's pixel (`level_px`, full-resolution px) it is searched at. With the
// vertices' projections; nullopt where part of the model is behind the camera.
struct ProjectionMask {
  cv::Mat mask;
  Vec2 origin = Vec2::Zero();
  double ms = 1.0;  // image px per mask px
  std::vector<std::optional<Vec2>> uv;

  Vec2 to_mask(const Vec2& p) const { return Vec2((p.x() - origin.x()) / ms, (p.y() - origin.y()) / ms); }
  bool inside(const Vec2& q) const {
    const int x = round_half_away(q.x()), y = round_half_away(q.y());
    return x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<std::uint8_t>(y, x) != 0;
  }
};

std::optional<ProjectionMask> project_model(const EdgeMesh& m, const Pose& pose, const PreparedView& v,
                                            const camera::CameraIntrinsics& K, const std::vector<char>& front,
                                            double level_px) {
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
  out.ms = std::max({1.0, extent.maxCoeff() / 1000.0, level_px / 2});
  out.mask = cv::Mat::zeros(static_cast<int>(std::ceil(extent.y() / out.ms)) + 1,
                            static_cast<int>(std::ceil(extent.x() / out.ms)) + 1, CV_8UC1);
  std::vector<cv::Point> poly;
  for (const auto& facet : m.facets) {
    if (m.closed && !front[facet.triangle]) continue;
    const auto& t = facet.loop;
    const std::size_t corners = t.size();
    poly.clear();
    for (std::size_t k = 0; k < corners; ++k) {
      const Vec3 A = pose.R * m.vertices[t[k]] + pose.t, B = pose.R * m.vertices[t[(k + 1) % corners]] + pose.t;
      const Vec2 &a = *out.uv[t[k]], &b = *out.uv[t[(k + 1) % corners]];
      const double len = (b - a).norm() / out.ms;
      // Subdivided where the distortion bows the side by more than the vertices' quarter pixel.
      const auto middle = project(K, v, 0.5 * (A + B));
      if (!middle) return std::nullopt;
      const bool bowed = (*middle - 0.5 * (a + b)).norm() / out.ms > 0.25;
      const int n = bowed ? std::clamp(static_cast<int>(std::ceil(len / 8.0)), 1, 64) : 1;
      for (int j = 0; j < n; ++j) {
        const auto p = project(K, v, A + (B - A) * (double(j) / n));
        if (!p) return std::nullopt;
        const Vec2 q = out.to_mask(*p) * 4.0;  // shift = 2: quarter-pixel vertices
        poly.emplace_back(round_half_away(q.x()), round_half_away(q.y()));
      }
    }
    // A convex facet's projection, its sides bowed by the distortion alone, is monotonic in y.
    cv::fillConvexPoly(out.mask, poly, cv::Scalar(255), cv::LINE_8, 2);
  }
  return out;
}

// d(projection · normal)/d(δ, δt) of the point X (board frame) of the model at `pose`, from the
// projection's derivative by the camera-frame point (distortion included).
Eigen::Matrix<double, 1, 6> sample_jacobian(const Eigen::Matrix<double, 2, 3>& d_uv_d_camera, const PreparedView& v,
                                            const Pose& pose, const Vec3& X, const Vec2& normal) {
  Eigen::Matrix<double, 3, 6> dX;
  dX.leftCols<3>() = -skew(X - pose.t);
  dX.rightCols<3>() = Mat3::Identity();
  return normal.transpose() * d_uv_d_camera * v.R_cb * dX;
}

// The outer contour samples of one view at `level` with their edge measurements; the
// attachments' outline is measured only `what.attachments` (for score_with_attachments, once).
void gather(const EdgeMesh& m, const Pose& pose, const PreparedView& v, const camera::CameraIntrinsics& K, int level,
            double search_px, const SilhouetteOptions& o, GatherWhat what, std::vector<Sample>& out,
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
  const auto projection = project_model(m, pose, v, K, front, scale);
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
    const auto long_edge = long_edge_of(a_antenna, b_antenna);
    if (long_edge && !o.long_edges[*long_edge]) continue;
    const int n = static_cast<int>(std::floor((*pm.uv[e.b] - *pm.uv[e.a]).norm() / spacing));
    const Vec3 A = pose.R * a_antenna + pose.t, B = pose.R * b_antenna + pose.t;
    for (int j = 0; j < n; ++j) {
      const double s = (j + 0.5) / n;
      const bool attachment = !on_box(a_antenna + (b_antenna - a_antenna) * s);
      if (attachment && !what.attachments) continue;
      const Vec3 X = A + (B - A) * s;
      Eigen::Matrix<double, 2, 3> d_uv_d_camera;
      const auto p = project(K, v, X, d_uv_d_camera);
      if (!p) continue;
      const Vec2 d = (d_uv_d_camera * (v.R_cb * (B - A))).normalized();  // the projected edge's tangent
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
      const Eigen::Matrix<double, 1, 6> J =
          what.jacobians ? sample_jacobian(d_uv_d_camera, v, pose, X, normal) : Eigen::Matrix<double, 1, 6>::Zero();
      const double depth = (v.R_cb * X + v.t_cb).z();
      out.push_back({normal, *edge * scale, J, static_cast<std::uint32_t>(ei), 0.5 * (K.fx + K.fy) / depth,
                     long_edge.has_value()});
    }
  }
}

}  // namespace

Gathered gather_all(const EdgeMesh& m, const Pose& pose, const std::vector<PreparedView>& views,
                    const camera::CameraIntrinsics& K, int level, double search_px, const SilhouetteOptions& o,
                    GatherWhat what) {
  Gathered g;
  g.per_view.resize(views.size());
  auto& counts = g.per_view_counts;
  counts.resize(views.size());
  cv::parallel_for_(cv::Range(0, static_cast<int>(views.size())), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i)
      gather(m, pose, views[i], K, level, search_px, o, what, g.per_view[i], counts[i]);
  });
  for (std::size_t i = 0; i < views.size(); ++i) {
    g.counts += counts[i];
    g.views_with_samples += g.per_view[i].empty() ? 0 : 1;
  }
  return g;
}

PreparedViews prepare_views(const EdgeMesh& m, const std::vector<Pose>& poses, const std::vector<SilhouetteView>& views,
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
    auto box = projected_box(intrinsics, v, m, poses.front());
    for (std::size_t k = 1; k < poses.size() && box; ++k) {
      const auto more = projected_box(intrinsics, v, m, poses[k]);
      box = more ? std::optional<cv::Rect2d>(*box | *more) : std::nullopt;
    }
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
      const auto& in = views[i];
      const cv::Rect crop(static_cast<int>(v.offset.x()), static_cast<int>(v.offset.y()), v.size.width, v.size.height);
      const double gamma = options.gamma, sigma = options.smoothing_sigma_px;
      const EdgeLevels levels = in.edges && in.edges->serves(gamma, sigma)
                                    ? in.edges->gradients(crop, out.top + 1, gamma, sigma)
                                    : EdgePyramid(in.image, EdgePyramidSettings::single_use(gamma, sigma))
                                          .gradients(crop, out.top + 1, gamma, sigma);
      v.offset = Vec2(levels.crop.x, levels.crop.y);
      v.size = levels.crop.size();
      const bool with_mask = !in.occluders.empty() || !in.background_edges.empty();
      const bool kept_masks = with_mask && in.masks && in.edges && in.edges->serves(gamma, sigma);
      for (int l = 0; l <= out.top; ++l) {
        cv::Mat gx = levels.gx[static_cast<std::size_t>(l)], gy = levels.gy[static_cast<std::size_t>(l)];
        if (with_mask) {
          // The shared images stay as they are: this view's known objects are its own.
          const double guard = options.mask_guard_px;
          const auto masked = kept_masks ? in.masks->masked(in, gx, gy, v.offset, l, guard)
                                         : masked_edges(known_object_mask(in, v.offset, gx.size(), l, guard), gx, gy);
          v.mask.push_back(masked.mask);
          gx = masked.gx, gy = masked.gy;
        }
        v.gx.push_back(gx);
        v.gy.push_back(gy);
      }
    }
  });
  return out;
}

}  // namespace antpose::registration::detail
