#include "antpose/registration/face_plane.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <utility>

namespace antpose::registration {
namespace {

// A long face in the antenna frame: outward normal n, e_u along the long axis, e_v = n × e_u
// across it; the plane at n·q = half_n, its flat part |u| ≤ half_u, |v| ≤ half_v.
struct Face {
  Vec3 n, e_u, e_v;
  double half_n = 0, half_u = 0, half_v = 0;
};

// The long faces whose outward normal points towards the mean viewpoint.
std::vector<Face> seen_faces(const Iso3& T_board_antenna, const Vec3& size_m, double edge_radius_m,
                             const std::vector<Vec3>& viewpoints_board, const FacePlaneOptions& o) {
  const Vec3 towards = T_board_antenna.inverse() * centroid(viewpoints_board);
  std::vector<Face> out;
  for (const int axis : {0, 1})
    for (const double sign : {1.0, -1.0}) {
      Face f;
      f.n = sign * Vec3::Unit(axis);
      f.e_u = Vec3::UnitZ();
      f.e_v = f.n.cross(f.e_u);
      f.half_n = size_m[axis] / 2;
      f.half_u = o.end_fraction * size_m.z() / 2;
      f.half_v = size_m[1 - axis] / 2 - edge_radius_m - o.edge_margin_m;
      if (f.n.dot(towards) > 0 && f.half_v > 0) out.push_back(f);
    }
  return out;
}

// The plane d = c₀ + b·u + c·v through the (u, v, d) points: coefficients, the inverse normal
// matrix, the residual variance, the points' extent along u and v, and how many `cell_m` squares
// of the face they occupy.
struct PlaneFit {
  Vec3 coefficients = Vec3::Zero();
  Mat3 normal_inverse = Mat3::Zero();
  double variance = 0.0;
  double span_u = 0.0, span_v = 0.0;
  std::size_t n = 0;
  std::size_t cells = 0;  // cell_m squares the points occupy
};

std::optional<PlaneFit> least_squares(const std::vector<Vec3>& uvd, double cell_m) {
  if (uvd.size() < 4) return std::nullopt;
  Mat3 AtA = Mat3::Zero();
  Vec3 Atd = Vec3::Zero();
  Vec2 lo = Vec2::Constant(1e300), hi = Vec2::Constant(-1e300);
  for (const Vec3& p : uvd) {
    const Vec3 a(1.0, p.x(), p.y());
    AtA += a * a.transpose();
    Atd += a * p.z();
    lo = lo.cwiseMin(p.head<2>()), hi = hi.cwiseMax(p.head<2>());
  }
  const Eigen::FullPivLU<Mat3> lu(AtA);
  if (!lu.isInvertible()) return std::nullopt;
  PlaneFit f;
  f.normal_inverse = lu.inverse();
  f.coefficients = f.normal_inverse * Atd;
  double ss = 0.0;
  for (const Vec3& p : uvd) ss += std::pow(p.z() - f.coefficients.dot(Vec3(1.0, p.x(), p.y())), 2);
  f.n = uvd.size();
  f.variance = ss / static_cast<double>(f.n - 3);
  f.span_u = hi.x() - lo.x(), f.span_v = hi.y() - lo.y();
  std::set<std::pair<long, long>> cells;
  for (const Vec3& p : uvd)
    cells.emplace(std::lround(std::floor(p.x() / cell_m)), std::lround(std::floor(p.y() / cell_m)));
  f.cells = cells.size();
  return f;
}

// The face's points (u, v, d about its registered plane), fitted and re-gated about the fit.
std::optional<PlaneFit> fit_face(const std::vector<Vec3>& points_antenna, const Face& face,
                                 const FacePlaneOptions& o) {
  std::vector<Vec3> all;
  for (const Vec3& q : points_antenna) {
    const Vec3 uvd(q.dot(face.e_u), q.dot(face.e_v), q.dot(face.n) - face.half_n);
    if (std::abs(uvd.x()) <= face.half_u && std::abs(uvd.y()) <= face.half_v && std::abs(uvd.z()) < o.gate_m)
      all.push_back(uvd);
  }
  std::optional<PlaneFit> fit;
  Vec3 plane = Vec3::Zero();
  double gate = o.gate_m;
  for (int k = 0; k < o.iterations; ++k) {
    std::vector<Vec3> in;
    for (const Vec3& p : all)
      if (std::abs(p.z() - plane.dot(Vec3(1.0, p.x(), p.y()))) < gate) in.push_back(p);
    fit = least_squares(in, o.correlation_m);
    if (!fit) return std::nullopt;
    plane = fit->coefficients;
    gate = std::max(o.min_gate_m, o.inlier_sigmas * std::sqrt(fit->variance));
  }
  return fit;
}

// One face's plane against the registered face, where its points cover it as a plane's would.
std::optional<FacePlane> face_plane(const std::vector<Vec3>& points_antenna, const Face& face, const Mat3& R,
                                    const Mat3& outline_covariance_board, const FacePlaneOptions& o) {
  const auto fit = fit_face(points_antenna, face, o);
  if (!fit || fit->n < o.min_points || fit->span_u < o.min_cover_fraction * 2 * face.half_u ||
      fit->span_v < o.min_cover_fraction * 2 * face.half_v || std::sqrt(fit->variance) > o.max_rms_m)
    return std::nullopt;
  const double n_eff = static_cast<double>(std::min(fit->n, fit->cells));
  Eigen::Matrix2d slopes_cov = fit->variance * fit->normal_inverse.bottomRightCorner<2, 2>() * (fit->n / n_eff);
  slopes_cov(0, 0) += std::pow(o.flatness_m / (fit->span_u / 2), 2);
  slopes_cov(1, 1) += std::pow(o.flatness_m / (fit->span_v / 2), 2);
  // ω = c·e_u − b·e_v (file comment): the turn from the slopes, J = [−e_v, e_u]; H = Jᵀ back.
  Eigen::Matrix<double, 3, 2> J;
  J.col(0) = -face.e_v, J.col(1) = face.e_u;
  FacePlane plane;
  plane.normal_antenna = face.n;
  plane.points = fit->n;
  plane.rms_m = std::sqrt(fit->variance);
  plane.slopes = fit->coefficients.tail<2>();
  plane.turn_board = R * (J * plane.slopes);
  plane.covariance_board = R * J * slopes_cov * J.transpose() * R.transpose();
  const Eigen::Matrix2d S = slopes_cov + J.transpose() * R.transpose() * outline_covariance_board * R * J;
  plane.chi2 = plane.slopes.dot(S.ldlt().solve(plane.slopes));
  plane.disagrees = plane.chi2 > o.max_chi2;
  return plane;
}

}  // namespace

OptionProblems FacePlaneOptions::Check() const {
  OptionProblems p;
  p.require(gate_m > 0 && min_gate_m > 0 && min_gate_m <= gate_m, "gate_m, min_gate_m", "0 < min_gate_m ≤ gate_m");
  p.require(end_fraction > 0 && end_fraction <= 1, "end_fraction", "in (0, 1]");
  p.require(edge_margin_m >= 0, "edge_margin_m", "≥ 0");
  p.require(inlier_sigmas > 0, "inlier_sigmas", "positive");
  p.require(iterations >= 1, "iterations", "at least 1");
  p.require(min_points >= 4, "min_points", "at least 4");
  p.require(min_cover_fraction >= 0 && min_cover_fraction <= 1, "min_cover_fraction", "in [0, 1]");
  p.require(correlation_m > 0 && flatness_m >= 0, "correlation_m, flatness_m", "correlation > 0, flatness ≥ 0");
  p.require(max_rms_m > 0, "max_rms_m", "positive");
  p.require(max_chi2 > 0, "max_chi2", "positive");
  return p;
}

std::vector<FacePlane> fit_face_planes(const PointCloud& points_board, const Iso3& T_board_antenna,
                                       const Vec3& size_m, double edge_radius_m,
                                       const std::vector<Vec3>& viewpoints_board,
                                       const Mat3& outline_covariance_board, const FacePlaneOptions& o) {
  throw_unless_ok(o.Check(), "FacePlaneOptions");
  std::vector<FacePlane> out;
  if (!o.enabled || points_board.empty() || viewpoints_board.empty()) return out;
  const auto points_antenna = transformed(points_board, T_board_antenna.inverse()).points;
  for (const Face& face : seen_faces(T_board_antenna, size_m, edge_radius_m, viewpoints_board, o))
    if (auto plane = face_plane(points_antenna, face, T_board_antenna.linear(), outline_covariance_board, o))
      out.push_back(*plane);
  return out;
}

std::string face_name(const Vec3& normal_antenna) {
  const int axis = std::abs(normal_antenna.x()) > std::abs(normal_antenna.y()) ? 0 : 1;
  return std::string(normal_antenna[axis] >= 0 ? "+" : "-") + (axis == 0 ? "x" : "y");
}

}  // namespace antpose::registration
