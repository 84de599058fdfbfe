#include "antpose/calibration/camera_imu.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>

#include "antpose/calibration/camera_imu_photos.hpp"
#include "antpose/calibration/least_squares.hpp"
#include "antpose/camera/camera_model.hpp"
#include "antpose/core/statistics.hpp"
#include "antpose/orientation/gyro_integration.hpp"

namespace antpose::calibration {

namespace detail {

void warn(Diagnostics& diagnostics, std::vector<std::string>& warnings, std::string message) {
  warnings.push_back(message);
  diagnostics.warn(std::move(message));
}

std::string describe(const PhotoObservation& p, std::size_t index) {
  return p.name.empty() ? fmt::format("photo {}", index) : p.name;
}

Mat3 device_rotation(const orientation::OrientationTrack& track, double t) {
  return track.at(std::clamp(t, track.t.front(), track.t.back())).q_world_device.toRotationMatrix();
}

std::vector<UsablePhoto> photos_in_track(const std::vector<PhotoObservation>& photos,
                                         const orientation::OrientationTrack& track, double dt,
                                         Diagnostics& diagnostics, std::vector<std::string>* warnings) {
  if (track.empty()) throw MeasurementError(fmt::format("orientation track '{}' is empty", track.method));
  std::vector<UsablePhoto> out;
  for (std::size_t i = 0; i < photos.size(); ++i) {
    const Mat3& R = photos[i].R_camera_board;
    if (!std::isfinite(photos[i].t_shot) || !R.allFinite() ||
        (R.transpose() * R - Mat3::Identity()).cwiseAbs().maxCoeff() > 1e-6 || R.determinant() < 0)
      throw MeasurementError(fmt::format("{}: shot time {} or R_camera_board is not a finite rotation",
                                         describe(photos[i], i), photos[i].t_shot));
    const double t = photos[i].t_shot + dt;
    if (!track.contains(t)) {
      if (warnings)
        warn(diagnostics, *warnings,
             fmt::format("{} (t = {:.3f} s) lies outside the orientation track '{}' [{:.3f}, {:.3f}] s; left out",
                         describe(photos[i], i), photos[i].t_shot, track.method, track.t.front(), track.t.back()));
      continue;
    }
    out.push_back({i, track.at(t).q_world_device.toRotationMatrix()});
  }
  return out;
}

}  // namespace detail

using detail::describe;
using detail::UsablePhoto;
using detail::kNaN;
using detail::photos_in_track;
using detail::warn;

namespace {

Vec3 board_axis(BoardAxis axis) { return Vec3::Unit(static_cast<int>(axis)); }

double wrapped_difference(double a, double b) { return wrap_pi(a - b); }

// ---- thesis method ----------------------------------------------------------------------------

/// Weight of a reference line: w1 (G), w2 (N), w3 (N of a steep axis). An axis is steep when its
/// G angle — measured on the same placement if there is such a line, else predicted with X —
/// is within steep_axis_deg of 0 or 180°.
struct LineWeighting {
  double weight = 0.0;
  bool steep = false;
};

LineWeighting line_weight(const BoardReferenceLine& line, const std::vector<BoardReferenceLine>& placement_lines,
                          const std::vector<Mat3>& predicted_R_world_board, const ThesisOptions& options) {
  if (line.ref == AngleReference::kGravity) return {options.w1, false};
  double g = kNaN;
  for (const auto& other : placement_lines)
    if (other.axis == line.axis && other.ref == AngleReference::kGravity) g = other.angle;
  if (std::isnan(g) && !predicted_R_world_board.empty()) {
    double sum = 0.0;
    for (const auto& R : predicted_R_world_board) sum += reference_angle(R, line.axis, AngleReference::kGravity);
    g = sum / static_cast<double>(predicted_R_world_board.size());
  }
  const double steep_limit = deg2rad(options.steep_axis_deg);
  const bool steep = !std::isnan(g) && std::min(g, std::numbers::pi - g) < steep_limit;
  return {steep ? options.w3 : options.w2, steep};
}

/// One photo × line term: the predicted angle of axis k of R_world_device exp(x) u_device.
struct ThesisResidual {
  Mat3 R_world_device;
  Vec3 u_device;  // X0 R_camera_board e_k
  AngleReference ref;
  double measured;
  double weight;

  template <typename T>
  bool operator()(const T* x, T* residual) const {
    const T u[3] = {T(u_device.x()), T(u_device.y()), T(u_device.z())};
    T w[3];
    ceres::AngleAxisRotatePoint(x, u, w);
    T v[3];
    for (int r = 0; r < 3; ++r) v[r] = R_world_device(r, 0) * w[0] + R_world_device(r, 1) * w[1] + R_world_device(r, 2) * w[2];
    if (ref == AngleReference::kGravity) {
      // atan2(|v_horizontal|, −v_up): accurate near 0 and 180° (acos is not); the tiny constant
      // keeps the derivative finite for an exactly vertical axis.
      const T predicted = ceres::atan2(ceres::sqrt(v[0] * v[0] + v[1] * v[1] + T(1e-30)), -v[2]);
      residual[0] = T(weight) * (predicted - T(measured));
    } else {
      const T d = ceres::atan2(v[0], v[1]) - T(measured);  // clockwise from north: atan2(east, north)
      residual[0] = T(weight) * ceres::atan2(ceres::sin(d), ceres::cos(d));
    }
    return true;
  }
};

/// Covariance of the thesis fit's single 3-parameter block. The residuals of one placement share
/// its level/compass errors and the track's heading error there, so they are not independent:
/// with G ≥ 4 placements the cluster-robust (sandwich) estimator
///   (JᵀJ)⁻¹ [Σ_g (J_gᵀ r_g)(J_gᵀ r_g)ᵀ] (JᵀJ)⁻¹ · G/(G−1)
/// (Liang & Zeger, Biometrika 73(1), 1986) is used; with fewer, the ordinary σ̂² (JᵀJ)⁻¹, which
/// is then optimistic.
Mat3 thesis_covariance(ceres::Problem& problem, const std::vector<std::size_t>& cluster, std::size_t residuals) {
  double cost = 0.0;
  std::vector<double> r;
  ceres::CRSMatrix crs;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, &r, nullptr, &crs);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(crs.num_rows, crs.num_cols);
  for (int i = 0; i < crs.num_rows; ++i)
    for (int k = crs.rows[i]; k < crs.rows[i + 1]; ++k) J(i, crs.cols[k]) = crs.values[k];
  const Mat3 H = J.transpose() * J;
  Eigen::FullPivLU<Mat3> lu(H);
  if (!lu.isInvertible() || residuals <= 3) return Mat3::Zero();
  const Mat3 H_inv = lu.inverse();
  std::map<std::size_t, Vec3> score;
  for (int i = 0; i < crs.num_rows; ++i) {
    auto [it, fresh] = score.try_emplace(cluster[static_cast<std::size_t>(i)], Vec3::Zero());
    it->second += J.row(i).transpose() * r[static_cast<std::size_t>(i)];
  }
  const double G = static_cast<double>(score.size());
  if (G < 4) return H_inv * (2.0 * cost / static_cast<double>(residuals - 3));
  Mat3 meat = Mat3::Zero();
  for (const auto& [g, v] : score) meat += v * v.transpose();
  return H_inv * meat * H_inv * (G / (G - 1.0));
}

}  // namespace

std::vector<PhotoObservation> photo_observations(const Capture& capture,
                                                 const std::vector<camera::PhotoBoardPose>& poses) {
  const auto placements = shot_placements(capture);
  std::vector<PhotoObservation> out;
  for (const auto& p : poses) {
    if (!p.pose) continue;
    if (p.shot_index >= capture.shots.size())
      throw std::invalid_argument(fmt::format("photo_observations: shot index {} out of range", p.shot_index));
    const auto& shot = capture.shots[p.shot_index];
    PhotoObservation o;
    o.t_shot = p.t;
    o.placement = placements[p.shot_index];
    o.R_camera_board = p.pose->R_camera_board;
    o.cov_R_camera_board = p.pose->covariance.topLeftCorner<3, 3>();
    o.name = fmt::format("shot {} ({})", shot.index, p.image);
    out.push_back(std::move(o));
  }
  return out;
}

double reference_angle(const Mat3& R_world_board, BoardAxis axis, AngleReference ref) {
  const Vec3 v = R_world_board * board_axis(axis);
  if (ref == AngleReference::kGravity) return std::atan2(v.head<2>().norm(), -v.z());
  if (v.head<2>().norm() == 0.0) return kNaN;
  return wrap_2pi(std::atan2(v.x(), v.y()));
}

AngleErrorTable reference_angle_errors(const std::vector<PhotoObservation>& photos, const BoardReference& reference,
                                       const orientation::OrientationTrack& track, const Mat3& R_device_camera,
                                       double time_offset_s, const ThesisOptions& options, std::string matrix_label) {
  Diagnostics quiet;
  const auto usable = photos_in_track(photos, track, time_offset_s, quiet, nullptr);
  AngleErrorTable table;
  table.method = track.method;
  table.matrix = std::move(matrix_label);
  double g_sum_all = 0, n_sum_all = 0;
  std::size_t g_count_all = 0, n_count_all = 0;
  table.overall.placement = "all";
  for (const auto& placement : reference.placements()) {
    const auto lines = reference.lines_of(placement);
    std::vector<Mat3> predicted;
    for (const auto& u : usable)
      if (photos[u.index].placement == placement)
        predicted.push_back(u.R_world_device * R_device_camera * photos[u.index].R_camera_board);
    AngleErrorRow row;
    row.placement = placement;
    row.photos = predicted.size();
    double g_sum = 0, n_sum = 0;
    std::size_t g_count = 0, n_count = 0;
    for (const auto& line : lines) {
      const auto lw = line_weight(line, lines, predicted, options);
      if (lw.weight == 0.0) {
        row.n_lines_steep += line.ref == AngleReference::kNorth ? 1 : 0;
        continue;
      }
      (line.ref == AngleReference::kGravity ? row.g_lines : row.n_lines) += 1;
      for (const auto& R : predicted) {
        const double a = reference_angle(R, line.axis, line.ref);
        if (std::isnan(a)) continue;
        if (line.ref == AngleReference::kGravity) {
          g_sum += std::abs(a - line.angle);
          ++g_count;
        } else {
          n_sum += std::abs(wrapped_difference(a, line.angle));
          ++n_count;
        }
      }
    }
    if (g_count) row.downtilt_error_deg = rad2deg(g_sum / static_cast<double>(g_count));
    if (n_count) row.azimuth_error_deg = rad2deg(n_sum / static_cast<double>(n_count));
    g_sum_all += g_sum, n_sum_all += n_sum, g_count_all += g_count, n_count_all += n_count;
    table.overall.photos += row.photos;
    table.overall.g_lines += row.g_lines;
    table.overall.n_lines += row.n_lines;
    table.overall.n_lines_steep += row.n_lines_steep;
    table.placements.push_back(std::move(row));
  }
  if (g_count_all) table.overall.downtilt_error_deg = rad2deg(g_sum_all / static_cast<double>(g_count_all));
  if (n_count_all) table.overall.azimuth_error_deg = rad2deg(n_sum_all / static_cast<double>(n_count_all));
  return table;
}

ThesisCalibration calibrate_thesis(const std::vector<PhotoObservation>& photos, const BoardReference& reference,
                                   const orientation::OrientationTrack& track, const ThesisOptions& options,
                                   Diagnostics& diagnostics) {
  ThesisCalibration out;
  out.method = track.method;
  if (!(options.w1 >= 0 && options.w2 >= 0 && options.w3 >= 0))
    throw std::invalid_argument("calibrate_thesis: weights must be non-negative");
  if (track.world != "enu-magnetic")
    warn(diagnostics, out.warnings,
         fmt::format("orientation track '{}' is {}, but board_reference N angles are magnetic (compass)", track.method,
                     track.world));
  const Mat3 X0 = options.start == ThesisOptions::Start::kNominal   ? camera::nominal_R_device_camera()
                  : options.start == ThesisOptions::Start::kIdentity ? Mat3::Identity()
                                                                     : nearest_rotation(options.R_start);
  const auto usable = photos_in_track(photos, track, options.time_offset_s, diagnostics, &out.warnings);

  double x[3] = {0.0, 0.0, 0.0};  // X = exp(x) X0, x a device-frame rotation vector
  ceres::Problem problem;
  std::vector<std::size_t> cluster;  // placement of each residual
  std::size_t placement_index = 0;
  for (const auto& placement : reference.placements()) {
    ++placement_index;
    const auto lines = reference.lines_of(placement);
    std::vector<const UsablePhoto*> members;
    std::vector<Mat3> predicted;
    for (const auto& u : usable)
      if (photos[u.index].placement == placement) {
        members.push_back(&u);
        predicted.push_back(u.R_world_device * X0 * photos[u.index].R_camera_board);
      }
    bool had_n = false, kept_n = false;
    for (const auto& line : lines) {
      const auto lw = line_weight(line, lines, predicted, options);
      if (line.ref == AngleReference::kNorth) {
        had_n = true;
        kept_n = kept_n || lw.weight > 0.0;
      }
      if (lw.weight == 0.0) continue;
      for (const auto* u : members) {
        const Vec3 u_device = X0 * photos[u->index].R_camera_board * board_axis(line.axis);
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<ThesisResidual, 1, 3>(
                                     new ThesisResidual{u->R_world_device, u_device, line.ref, line.angle, lw.weight}),
                                 nullptr, x);
        cluster.push_back(placement_index);
        ++out.residuals;
      }
    }
    if (had_n && !kept_n)
      warn(diagnostics, out.warnings,
           fmt::format("placement '{}': every N line is of an axis within {}° of the vertical (ill-defined azimuth, "
                       "weight w3 = 0); the placement does not constrain the heading",
                       placement, options.steep_axis_deg));
  }
  if (out.residuals == 0)
    throw MeasurementError(fmt::format(
        "thesis method: no photo of a placement in {} lies inside orientation track '{}' with a reference line of "
        "non-zero weight",
        reference.file.string(), track.method));
  const auto summary = solve_levenberg_marquardt(problem, options.max_iterations, 1e-12);
  out.iterations = static_cast<int>(summary.iterations.size());
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.R_device_camera = exp_so3(Vec3(x[0], x[1], x[2])) * X0;
  out.rms_weighted_deg = rad2deg(std::sqrt(2.0 * summary.final_cost / static_cast<double>(out.residuals)));
  out.covariance = thesis_covariance(problem, cluster, out.residuals);
  if (!out.converged)
    warn(diagnostics, out.warnings,
         fmt::format("thesis method ({}): Levenberg–Marquardt stopped without convergence ({})", track.method,
                     summary.message));
  out.optimised = reference_angle_errors(photos, reference, track, out.R_device_camera, options.time_offset_s, options,
                                         "optimised");
  out.nominal = reference_angle_errors(photos, reference, track, camera::nominal_R_device_camera(),
                                       options.time_offset_s, options, "nominal");
  return out;
}

namespace {
std::string cell(double v) { return std::isnan(v) ? std::string("     -") : fmt::format("{:6.2f}", v); }
}  // namespace

std::string format_angle_error_table(const AngleErrorTable& table) {
  std::string s = fmt::format("orientation '{}', R_device_camera {}: mean absolute errors (deg)\n", table.method,
                              table.matrix);
  s += fmt::format("{:<20} {:>6} {:>3} {:>3} {:>9} {:>9}\n", "placement", "photos", "G", "N", "downtilt", "azimuth");
  auto row = [&](const AngleErrorRow& r) {
    s += fmt::format("{:<20} {:>6} {:>3} {:>3}    {}    {}\n", r.placement, r.photos, r.g_lines, r.n_lines,
                     cell(r.downtilt_error_deg), cell(r.azimuth_error_deg));
  };
  for (const auto& r : table.placements) row(r);
  row(table.overall);
  return s;
}

std::string format_thesis_tables(const std::vector<ThesisCalibration>& results) {
  std::string s;
  for (const auto& r : results) {
    s += fmt::format("orientation '{}': mean absolute errors (deg), optimised vs nominal R_device_camera\n", r.method);
    s += fmt::format("{:<20} {:>6} {:>3} {:>3} | {:>9} {:>9} | {:>9} {:>9}\n", "placement", "photos", "G", "N",
                     "downtilt", "(nominal)", "azimuth", "(nominal)");
    const auto n = r.optimised.placements.size();
    for (std::size_t i = 0; i <= n; ++i) {
      const auto& o = i < n ? r.optimised.placements[i] : r.optimised.overall;
      const auto& m = i < n ? r.nominal.placements[i] : r.nominal.overall;
      s += fmt::format("{:<20} {:>6} {:>3} {:>3} |    {}    {} |    {}    {}\n", o.placement, o.photos, o.g_lines,
                       o.n_lines, cell(o.downtilt_error_deg), cell(m.downtilt_error_deg), cell(o.azimuth_error_deg),
                       cell(m.azimuth_error_deg));
    }
    const Vec3 e = log_so3(camera::nominal_R_device_camera().transpose() * r.R_device_camera);
    s += fmt::format("R_device_camera = nominal · exp(({:.3f}, {:.3f}, {:.3f})°), 1σ ({:.3f}, {:.3f}, {:.3f})°\n\n",
                     rad2deg(e.x()), rad2deg(e.y()), rad2deg(e.z()), rad2deg(std::sqrt(r.covariance(0, 0))),
                     rad2deg(std::sqrt(r.covariance(1, 1))), rad2deg(std::sqrt(r.covariance(2, 2))));
  }
  return s;
}

// ---- reference-free method --------------------------------------------------------------------

Mat3 hand_eye_rotation(const std::vector<Mat3>& R_world_device, const std::vector<Mat3>& R_camera_board,
                       const std::vector<std::size_t>& group) {
  if (R_world_device.size() != R_camera_board.size() || group.size() != R_camera_board.size())
    throw std::invalid_argument("hand_eye_rotation: inputs differ in size");
  Mat3 H = Mat3::Zero();  // Σ β αᵀ, β = log B (camera), α = log A (device)
  for (std::size_t i = 0; i < group.size(); ++i)
    for (std::size_t j = i + 1; j < group.size(); ++j) {
      if (group[i] != group[j]) continue;
      const Vec3 alpha = log_so3(R_world_device[i].transpose() * R_world_device[j]);
      const Vec3 beta = log_so3(R_camera_board[i] * R_camera_board[j].transpose());
      H += beta * alpha.transpose();
    }
  // Kabsch: X = V diag(1, 1, det(V Uᵀ)) Uᵀ maximises tr(X H), i.e. minimises Σ ‖α − X β‖².
  Eigen::JacobiSVD<Mat3> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 D = Mat3::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  return svd.matrixV() * D * svd.matrixU().transpose();
}

Vec2 principal_point_rotation_sigma(const camera::CameraIntrinsics& intrinsics, const Vec2& principal_point_sigma_px) {
  return {principal_point_sigma_px.y() / intrinsics.fy, principal_point_sigma_px.x() / intrinsics.fx};
}

Vec3 ReferenceFreeCalibration::rotation_sigma_deg() const {
  return covariance.diagonal().cwiseMax(0.0).cwiseSqrt() * (180.0 / std::numbers::pi);
}

store::CameraImuCalibration ReferenceFreeCalibration::to_profile() const {
  store::CameraImuCalibration c;
  c.R_device_camera = R_device_camera;
  c.rotation_sigma_rad = covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  c.time_offset_s = time_offset_s;
  if (time_offset_estimated) c.time_offset_sigma_s = time_offset_sigma_s;
  c.method = "reference-free";
  return c;
}

}  // namespace antpose::calibration
