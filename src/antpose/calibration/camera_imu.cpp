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

#include "antpose/calibration/least_squares.hpp"
#include "antpose/camera/camera_model.hpp"
#include "antpose/core/statistics.hpp"
#include "antpose/orientation/gyro_integration.hpp"

namespace antpose::calibration {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

void warn(Diagnostics& diagnostics, std::vector<std::string>& warnings, std::string message) {
  warnings.push_back(message);
  diagnostics.warn(std::move(message));
}

std::string describe(const PhotoObservation& p, std::size_t index) {
  return p.name.empty() ? fmt::format("photo {}", index) : p.name;
}

/// R_world_device at `t`, clamped into the track's span (used only for the small excursions of a
/// time-offset search: photos outside the span are rejected before).
Mat3 device_rotation(const orientation::OrientationTrack& track, double t) {
  return track.at(std::clamp(t, track.t.front(), track.t.back())).q_world_device.toRotationMatrix();
}

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

struct UsablePhoto {
  std::size_t index;
  Mat3 R_world_device;
};

/// Photos inside the track (others warned about and left out), at IMU time t_shot + dt.
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

namespace {

/// One placement's photos and the gyroscope integrated across them.
struct Segment {
  std::string placement;
  std::vector<std::size_t> members;                // positions in FreeProblem::index
  std::optional<orientation::GyroIntegration> gyro;  // device(t) → device(t0), current bias
  Vec3 bias = Vec3::Zero();                        // accumulated bias correction (rad/s)
  std::array<double, 3> db{0, 0, 0};               // its increment in the current linearisation
  Mat3 B0 = Mat3::Identity();                      // R_gyro_board (gyro frame = device at t0)
  std::array<double, 3> b{0, 0, 0};                // board perturbation, gyro frame
  Mat3 board() const { return exp_so3(Vec3(b[0], b[1], b[2])) * B0; }
};

using Mat39 = Eigen::Matrix<double, 3, 9>;

/// Whitened residual of one photo in its segment's gyroscope frame:
///   r = L⁻¹ log( ΔR_ref exp(ω Δ) exp(J δb + J_G δg) exp(x) X0 R_camera_board R_gyro_board0ᵀ exp(−b) ),
/// with ΔR_ref, J = ΔR(t_shot + δt_ref) and its bias Jacobian, J_G its Jacobian with respect to
/// the gyroscope correction's elements δg (row-major δG; zero for a calibrated gyroscope), ω the
/// body rate there and Δ = δt − δt_ref (first order in Δ, δb and δg; the caller re-integrates
/// until all three vanish).
struct PreintegratedBoardResidual {
  Mat3 R_ref, J;
  Mat39 J_G;
  Vec3 omega;
  double dt_ref;
  Mat3 C;  // X0 R_camera_board R_gyro_board0ᵀ
  Mat3 W;  // L⁻¹

  template <typename T>
  bool operator()(const T* x, const T* b, const T* db, const T* dt, const T* dg, T* residual) const {
    using M3 = Eigen::Matrix<T, 3, 3>;
    const T delta = dt[0] - T(dt_ref);
    T w[3], jb[3];
    for (int r = 0; r < 3; ++r) {
      w[r] = T(omega[r]) * delta;
      jb[r] = T(J(r, 0)) * db[0] + T(J(r, 1)) * db[1] + T(J(r, 2)) * db[2];
      for (int c = 0; c < 9; ++c) jb[r] += T(J_G(r, c)) * dg[c];
    }
    const T minus_b[3] = {-b[0], -b[1], -b[2]};
    M3 Rw, Rj, Rx, Rb;
    ceres::AngleAxisToRotationMatrix(w, Rw.data());
    ceres::AngleAxisToRotationMatrix(jb, Rj.data());
    ceres::AngleAxisToRotationMatrix(x, Rx.data());
    ceres::AngleAxisToRotationMatrix(minus_b, Rb.data());
    const M3 M = R_ref.cast<T>() * Rw * Rj * Rx * C.cast<T>() * Rb;
    T e[3];
    ceres::RotationMatrixToAngleAxis(M.data(), e);
    for (int r = 0; r < 3; ++r) residual[r] = T(W(r, 0)) * e[0] + T(W(r, 1)) * e[1] + T(W(r, 2)) * e[2];
    return true;
  }
};

/// Prior on a segment's total bias correction: (bias + δb) / σ_b.
struct BiasPrior {
  Vec3 bias;
  double inv_sigma;
  template <typename T>
  bool operator()(const T* db, T* residual) const {
    for (int r = 0; r < 3; ++r) residual[r] = (T(bias[r]) + db[r]) * T(inv_sigma);
    return true;
  }
};

/// Prior on the total gyroscope correction of an uncalibrated gyroscope, element by element:
/// (G + δG)_rc / σ_rc, σ the scale-factor budget on the diagonal and the cross-axis budget off it.
struct GyroCorrectionPrior {
  Mat3 G;
  Mat3 inv_sigma;
  template <typename T>
  bool operator()(const T* dg, T* residual) const {
    for (int k = 0; k < 9; ++k) residual[k] = (T(G(k / 3, k % 3)) + dg[k]) * T(inv_sigma(k / 3, k % 3));
    return true;
  }
};

/// The samples of `series` that an integration over [t0, t1] reads (two either side), their rates
/// multiplied by M.
orientation::SensorSeries corrected_window(const orientation::SensorSeries& series, const Mat3& M, double t0,
                                           double t1) {
  const auto first = std::lower_bound(series.t.begin(), series.t.end(), t0) - series.t.begin();
  const auto last = std::upper_bound(series.t.begin(), series.t.end(), t1) - series.t.begin();
  const auto lo = static_cast<std::size_t>(std::max<std::ptrdiff_t>(0, first - 2));
  const auto hi = std::min(series.size(), static_cast<std::size_t>(last + 2));
  orientation::SensorSeries out;
  out.t.assign(series.t.begin() + static_cast<std::ptrdiff_t>(lo), series.t.begin() + static_cast<std::ptrdiff_t>(hi));
  out.v.reserve(hi - lo);
  for (std::size_t i = lo; i < hi; ++i) out.v.push_back(M * series.v[i]);
  return out;
}

struct FreeProblem {
  const std::vector<PhotoObservation>* photos = nullptr;
  const orientation::SensorSeries* gyroscope = nullptr;
  const ReferenceFreeOptions* options = nullptr;
  std::vector<std::size_t> index;  // used photos → input index
  std::vector<std::size_t> group;  // used photo → segment
  std::vector<Segment> segments;

  Mat3 X0 = Mat3::Identity();
  double x[3] = {0, 0, 0};
  double dt = 0.0;
  // Uncalibrated gyroscope: the accumulated correction G (ω ← (I + G) ω) and its increment δg
  // (row-major) in the current linearisation; both stay zero for a calibrated one.
  Mat3 G = Mat3::Zero();
  std::array<double, 9> dg{};

  Mat3 X() const { return exp_so3(Vec3(x[0], x[1], x[2])) * X0; }
  const PhotoObservation& photo(std::size_t k) const { return (*photos)[index[k]]; }
  bool estimate_gyro() const { return options->gyro_uncalibrated(); }

  /// Integration window of a segment: its shots plus the whole time-offset bracket.
  std::pair<double, double> window(const Segment& s) const {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (std::size_t k : s.members) lo = std::min(lo, photo(k).t_shot), hi = std::max(hi, photo(k).t_shot);
    return {lo + std::min(options->time_offset_min_s, dt) - 0.05, hi + std::max(options->time_offset_max_s, dt) + 0.05};
  }

  /// The segment's gyroscope integration with its bias, and with the correction I + G + ΔG.
  orientation::GyroIntegration integration(const Segment& s, const Mat3& dG = Mat3::Zero()) const {
    const auto [t0, t1] = window(s);
    if (G.isZero(0.0) && dG.isZero(0.0))
      return orientation::GyroIntegration(*gyroscope, t0, t1, s.bias, options->gyro_trapezoid);
    return orientation::GyroIntegration(corrected_window(*gyroscope, Mat3::Identity() + G + dG, t0, t1), t0, t1, s.bias,
                                        options->gyro_trapezoid);
  }

  void integrate(Segment& s) const { s.gyro.emplace(integration(s)); }

  /// J_G of every used photo at t_shot + dt: ΔR(t; G + ε E_c) = ΔR(t) exp(J_G[:, c] ε) by forward
  /// differences of re-integrations (the perturbation (ε E_c) ω is a time-varying bias, for which
  /// Forster et al.'s closed form (eq. 44) does not hold). ε = 1e-6 perturbs a 5 rad turn by 5 µrad:
  /// far above rounding, far below the curvature of log.
  std::vector<Mat39> gyro_correction_jacobians(const std::vector<bool>& use) const {
    std::vector<Mat39> out(index.size(), Mat39::Zero());
    if (!estimate_gyro()) return out;
    constexpr double kStep = 1e-6;
    for (const auto& seg : segments)
      for (int c = 0; c < 9; ++c) {
        Mat3 dG = Mat3::Zero();
        dG(c / 3, c % 3) = kStep;
        const auto perturbed = integration(seg, dG);
        for (std::size_t k : seg.members) {
          if (!use[k]) continue;
          const double t = photo(k).t_shot + dt;
          out[k].col(c) = log_so3(seg.gyro->at(t).R.transpose() * perturbed.at(t).R) / kStep;
        }
      }
    return out;
  }

  Mat3 device(std::size_t k, double offset) const { return segments[group[k]].gyro->at(photo(k).t_shot + offset).R; }

  /// Noise of photo k's residual (rad², gyro frame): PnP, the gyroscope's angle random walk since
  /// the segment start, and a floor.
  Mat3 photo_covariance(std::size_t k) const {
    const auto& o = *options;
    const auto& ph = photo(k);
    Mat3 cov_c = ph.cov_R_camera_board;
    Eigen::SelfAdjointEigenSolver<Mat3> es(0.5 * (cov_c + cov_c.transpose()));
    if (!cov_c.allFinite() || es.eigenvalues().minCoeff() <= 0.0)
      cov_c = Mat3::Identity() * std::pow(deg2rad(o.default_pnp_sigma_deg), 2);
    const auto& g = *segments[group[k]].gyro;
    const Mat3 R_gc = g.at(ph.t_shot + dt).R * X0;
    const double walk = o.gyro_noise_density * o.gyro_noise_density * std::max(0.0, ph.t_shot + dt - g.t0());
    return R_gc * cov_c * R_gc.transpose() +
           Mat3::Identity() * (walk + std::pow(deg2rad(o.sigma_floor_deg), 2));
  }

  /// Residual rotation vector of photo k at the current estimate (gyro frame, exact time).
  Vec3 residual(std::size_t k) const {
    return log_so3(device(k, dt) * X() * photo(k).R_camera_board * segments[group[k]].board().transpose());
  }

  /// Closed-form start at a time offset: hand–eye rotation from the gyroscope's relative rotations
  /// and chordal board means; returns a truncated (2°) cost for the time-offset search.
  double closed_form(double offset, Mat3& X, std::vector<Mat3>& boards) const {
    const std::size_t n = index.size();
    std::vector<Mat3> R_gd(n), R_cb(n);
    for (std::size_t k = 0; k < n; ++k) R_gd[k] = device(k, offset), R_cb[k] = photo(k).R_camera_board;
    X = options->R_start ? nearest_rotation(*options->R_start) : hand_eye_rotation(R_gd, R_cb, group);
    std::vector<std::vector<Mat3>> per(segments.size());
    for (std::size_t k = 0; k < n; ++k) per[group[k]].push_back(R_gd[k] * X * R_cb[k]);
    boards.resize(segments.size());
    for (std::size_t s = 0; s < segments.size(); ++s) boards[s] = chordal_mean(per[s]);
    const double cap = deg2rad(2.0);
    double cost = 0.0;
    for (std::size_t k = 0; k < n; ++k)
      cost += std::min(std::pow(rotation_distance(R_gd[k] * X * R_cb[k], boards[group[k]]), 2), cap * cap);
    return cost;
  }

  struct Solution {
    double cost = 0.0;
    std::size_t residuals = 0;
    bool converged = false;
    bool settled = false;  // the re-linearisation settled (else: the last round's figures)
    bool damped = false;   // δt's steps swung back and forth and were damped
    double dt_step = 0.0;  // δt's last undamped step, s
    std::optional<Mat3> cov_x;
    double var_dt = kNaN;
    double var_dt_fit = kNaN;   // with the gyroscope correction held (= var_dt without one)
    Mat3 var_G = Mat3::Zero();  // variances of G's elements
  };

  /// Covariance of x, δt and G at the solution of `problem`; σ(δt) also with G held, which is
  /// what the photos and the gyroscope's noise alone allow.
  void covariance(ceres::Problem& problem, bool free_dt, Solution& sol) {
    ceres::Covariance::Options co;
    co.algorithm_type = ceres::DENSE_SVD;
    co.null_space_rank = -1;
    ceres::Covariance full(co);
    std::vector<std::pair<const double*, const double*>> blocks = {{x, x}};
    if (free_dt) blocks.push_back({&dt, &dt});
    if (estimate_gyro()) blocks.push_back({dg.data(), dg.data()});
    if (!full.Compute(blocks, &problem)) return;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> c;
    full.GetCovarianceBlock(x, x, c.data());
    sol.cov_x = c;
    if (free_dt) full.GetCovarianceBlock(&dt, &dt, &sol.var_dt);
    sol.var_dt_fit = sol.var_dt;
    if (!estimate_gyro()) return;
    Eigen::Matrix<double, 9, 9, Eigen::RowMajor> cg;
    full.GetCovarianceBlock(dg.data(), dg.data(), cg.data());
    for (int k = 0; k < 9; ++k) sol.var_G(k / 3, k % 3) = cg(k, k);
    if (!free_dt) return;
    problem.SetParameterBlockConstant(dg.data());
    ceres::Covariance held(co);
    const std::vector<std::pair<const double*, const double*>> dt_block = {{&dt, &dt}};
    if (held.Compute(dt_block, &problem)) held.GetCovarianceBlock(&dt, &dt, &sol.var_dt_fit);
    problem.SetParameterBlockVariable(dg.data());
  }

  /// Solves with photos where `use[k]` (Huber loss when `robust`); after each round the bias and
  /// gyroscope-correction increments are folded into the integration and δt re-linearised, until
  /// δt moves less than 10 µs, the bias less than 1e-6 rad/s and G less than 1e-8 (at most 20
  /// rounds; the covariance is that of the last round when they do not settle).
  Solution solve(const std::vector<bool>& use, bool robust, bool free_dt, bool want_covariance) {
    constexpr int kRounds = 20;
    Solution sol;
    const double inv_sigma_b = 1.0 / options->gyro_bias_sigma_rad_s;
    double damping = 1.0, last_dt_step = 0.0;
    for (int round = 0; round < kRounds; ++round) {
      const double dt_ref = dt;
      const auto J_G = gyro_correction_jacobians(use);
      ceres::Problem problem;
      sol.residuals = 0;
      for (std::size_t k = 0; k < index.size(); ++k) {
        if (!use[k]) continue;
        auto& seg = segments[group[k]];
        const double t = photo(k).t_shot + dt_ref;
        const auto s = seg.gyro->at(t);
        const Mat3 W = Eigen::LLT<Mat3>(photo_covariance(k)).matrixL().solve(Mat3::Identity());
        const Mat3 C = X0 * photo(k).R_camera_board * seg.B0.transpose();
        auto* cost = new ceres::AutoDiffCostFunction<PreintegratedBoardResidual, 3, 3, 3, 3, 1, 9>(
            new PreintegratedBoardResidual{s.R, s.J, J_G[k], seg.gyro->rate(t), dt_ref, C, W});
        problem.AddResidualBlock(cost, robust ? new ceres::HuberLoss(options->huber_k) : nullptr, x, seg.b.data(),
                                 seg.db.data(), &dt, dg.data());
        ++sol.residuals;
      }
      for (auto& seg : segments)
        if (problem.HasParameterBlock(seg.db.data()))
          problem.AddResidualBlock(
              new ceres::AutoDiffCostFunction<BiasPrior, 3, 3>(new BiasPrior{seg.bias, inv_sigma_b}), nullptr,
              seg.db.data());
      if (estimate_gyro()) {
        Mat3 inv_sigma = Mat3::Constant(1.0 / options->gyro_cross_axis_sigma);
        inv_sigma.diagonal().setConstant(1.0 / options->gyro_scale_sigma);
        problem.AddResidualBlock(
            new ceres::AutoDiffCostFunction<GyroCorrectionPrior, 9, 9>(new GyroCorrectionPrior{G, inv_sigma}), nullptr,
            dg.data());
      } else {
        problem.SetParameterBlockConstant(dg.data());
      }
      if (!free_dt) problem.SetParameterBlockConstant(&dt);
      const auto summary = solve_levenberg_marquardt(problem, options->max_iterations, 1e-12);
      sol.cost = summary.final_cost;
      sol.converged = summary.termination_type == ceres::CONVERGENCE;
      double bias_step = 0.0;
      for (const auto& seg : segments) bias_step = std::max(bias_step, Vec3(seg.db[0], seg.db[1], seg.db[2]).norm());
      const Mat3 G_step = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(dg.data());
      // Re-linearising at the new δt is a fixed-point iteration, and the rate ω of the model is
      // constant over each gyroscope sample interval, so the model jumps where t_shot + δt crosses
      // a sample. Near such a kink, or where the rate changes fast about the shots (a phone slowing
      // into each view), the steps can swing back and forth about the optimum for ever; each
      // reversal halves them (damped fixed-point iteration), and δt has settled when the damped
      // step is below 10 µs. What is left of the undamped step (the kink's width) joins σ(δt).
      const double dt_step = dt - dt_ref;
      if (dt_step * last_dt_step < 0.0) damping *= 0.5;
      sol.settled =
          (!free_dt || std::abs(damping * dt_step) < 1e-5) && bias_step < 1e-6 && G_step.cwiseAbs().maxCoeff() < 1e-8;
      sol.damped = damping < 1.0;
      sol.dt_step = dt_step;
      if ((sol.settled || round + 1 == kRounds) && want_covariance) covariance(problem, free_dt, sol);
      if (sol.settled) break;
      dt = dt_ref + damping * dt_step;
      last_dt_step = damping * dt_step;
      // Fold the increments in: new bias and correction, re-integrated gyroscope; the board keeps
      // its attitude at the first photo's instant to first order (the Jacobians move ΔR, b absorbs
      // the rest).
      G += G_step;
      dg.fill(0.0);
      for (auto& seg : segments) {
        seg.bias += Vec3(seg.db[0], seg.db[1], seg.db[2]);
        seg.db = {0, 0, 0};
        integrate(seg);
      }
    }
    return sol;
  }
};

/// An uncalibrated gyroscope's scale and cross-axis errors can pass for a time offset: the
/// rotation they add to ΔR grows with the angle turned since the placement's start, as ω δt grows
/// with the rate at the shot. Where the photos fix δt (σ with the correction held ≤ the limit)
/// but the correction's uncertainty blurs it beyond the limit, the offset is refused rather than
/// fixed at a guess: the gyroscope, not the motion, is what is missing.
void refuse_offset_blurred_by_gyroscope(const ReferenceFreeCalibration& out, const ReferenceFreeOptions& options,
                                        double dt) {
  const double limit = options.max_time_offset_sigma_s;
  if (!(out.time_offset_sigma_fit_s <= limit)) return;
  throw MeasurementError(fmt::format(
      "camera–IMU calibration: the time offset {:.1f} ms has σ {:.1f} ms with the uncalibrated gyroscope's scale "
      "(1σ {:.1f} %) and cross-axis (1σ {:.1f} %) errors ({:.1f} ms without them), more than the {:.0f} ms "
      "allowed. Calibrate the gyroscope first (antpose calibrate imu, then pass that device with --device), or fix "
      "the time offset at a known value (--fixed-time-offset --time-offset S)",
      1e3 * dt, 1e3 * out.time_offset_sigma_s, 100.0 * options.gyro_scale_sigma, 100.0 * options.gyro_cross_axis_sigma,
      1e3 * out.time_offset_sigma_fit_s, 1e3 * limit));
}

/// The warning that every result of an uncalibrated gyroscope carries, with its figures.
void warn_uncalibrated_gyroscope(ReferenceFreeCalibration& out, Diagnostics& diagnostics) {
  const Vec3 scale = 100.0 * (out.gyro_correction.diagonal() - Vec3::Ones());
  const Vec3 scale_sigma = 100.0 * out.gyro_correction_sigma.diagonal();
  std::string message = fmt::format(
      "uncalibrated gyroscope: its scale errors, estimated with the photos, are ({:.2f}, {:.2f}, {:.2f}) % "
      "(1σ {:.2f}, {:.2f}, {:.2f} %); the σ of R_device_camera",
      scale.x(), scale.y(), scale.z(), scale_sigma.x(), scale_sigma.y(), scale_sigma.z());
  if (out.time_offset_estimated)
    message += fmt::format(" and of the time offset ({:.2f} ms; {:.2f} ms without the gyroscope's errors)",
                           1e3 * out.time_offset_sigma_s, 1e3 * out.time_offset_sigma_fit_s);
  message += " include its scale and cross-axis errors; 'antpose calibrate imu' removes them";
  warn(diagnostics, out.warnings, std::move(message));
}

}  // namespace

ReferenceFreeCalibration calibrate_reference_free(const std::vector<PhotoObservation>& photos,
                                                  const orientation::SensorSeries& gyroscope,
                                                  const orientation::OrientationTrack& track,
                                                  const ReferenceFreeOptions& options, Diagnostics& diagnostics,
                                                  const BoardReference* reference) {
  ReferenceFreeCalibration out;
  auto& warnings = out.warnings;
  if (gyroscope.size() < 2) throw MeasurementError("camera–IMU calibration: the gyroscope stream has fewer than 2 samples");
  if (!(options.gyro_bias_sigma_rad_s > 0.0))
    throw std::invalid_argument("calibrate_reference_free: gyro_bias_sigma_rad_s must be positive");
  if (!(options.gyro_scale_sigma >= 0.0 && options.gyro_cross_axis_sigma >= 0.0) ||
      (options.gyro_uncalibrated() && !(options.gyro_scale_sigma > 0.0 && options.gyro_cross_axis_sigma > 0.0)))
    throw std::invalid_argument(
        "calibrate_reference_free: gyro_scale_sigma and gyro_cross_axis_sigma must be both 0 or both positive");
  const auto usable = photos_in_track(photos, track, 0.0, diagnostics, &warnings);

  // Group by placement (order of first appearance) and drop placements that cannot help.
  std::vector<std::string> names;
  std::map<std::string, std::vector<std::size_t>> members;  // placement → input indexes
  for (const auto& u : usable) {
    const auto& p = photos[u.index].placement;
    if (!members.count(p)) names.push_back(p);
    members[p].push_back(u.index);
  }
  FreeProblem fp;
  fp.photos = &photos;
  fp.gyroscope = &gyroscope;
  fp.options = &options;
  fp.dt = options.time_offset_start_s;
  for (const auto& name : names) {
    const auto& m = members[name];
    if (m.size() < options.min_photos_per_placement) {
      warn(diagnostics, warnings,
           fmt::format("placement '{}' has {} usable photo(s), at least {} are needed; left out", name, m.size(),
                       options.min_photos_per_placement));
      continue;
    }
    double largest = 0.0;
    for (std::size_t a = 0; a < m.size(); ++a)
      for (std::size_t c = a + 1; c < m.size(); ++c)
        largest = std::max(largest, rotation_distance(photos[m[a]].R_camera_board, photos[m[c]].R_camera_board));
    if (rad2deg(largest) < options.min_view_change_deg) {
      warn(diagnostics, warnings,
           fmt::format("placement '{}': all {} photos were taken from one pose (largest relative rotation {:.2f}°, "
                       "need ≥ {}°): they cannot constrain R_device_camera (degenerate hand–eye); left out",
                       name, m.size(), rad2deg(largest), options.min_view_change_deg));
      continue;
    }
    Segment seg;
    seg.placement = name;
    for (std::size_t i : m) {
      seg.members.push_back(fp.index.size());
      fp.index.push_back(i);
      fp.group.push_back(fp.segments.size());
    }
    fp.integrate(seg);
    if (seg.gyro->longest_step_s() > options.max_gyro_gap_s) {
      warn(diagnostics, warnings,
           fmt::format("placement '{}': the gyroscope has a {:.3f} s gap at t = {:.3f} s between its photos, so the "
                       "phone's rotation there is unknown; left out",
                       name, seg.gyro->longest_step_s(), seg.gyro->longest_step_at()));
      fp.index.resize(fp.index.size() - m.size());
      fp.group.resize(fp.group.size() - m.size());
      continue;
    }
    fp.segments.push_back(std::move(seg));
  }
  if (fp.segments.empty())
    throw MeasurementError(fmt::format("camera–IMU calibration: no usable placement ({} photos given, {} inside the "
                                       "orientation track; see the warnings)",
                                       photos.size(), usable.size()));

  // Observability of the rotation: the relative camera rotations must not all share one axis.
  {
    Mat3 S = Mat3::Zero();
    std::size_t pairs = 0;
    for (std::size_t i = 0; i < fp.index.size(); ++i)
      for (std::size_t j = i + 1; j < fp.index.size(); ++j)
        if (fp.group[i] == fp.group[j]) {
          const Vec3 beta = log_so3(photos[fp.index[i]].R_camera_board * photos[fp.index[j]].R_camera_board.transpose());
          S += beta * beta.transpose();
          ++pairs;
        }
    const Eigen::SelfAdjointEigenSolver<Mat3> es(S / static_cast<double>(pairs));
    const double spread = std::sqrt(std::max(0.0, es.eigenvalues()(1)));
    if (rad2deg(spread) < options.min_axis_spread_deg)
      throw MeasurementError(fmt::format(
          "camera–IMU calibration: the views of every placement differ by rotations about one axis only (RMS rotation "
          "off that axis {:.2f}°, need ≥ {}°): R_device_camera is not observable (degenerate hand–eye). Take the "
          "photos of a placement from views tilted about two different axes",
          rad2deg(spread), options.min_axis_spread_deg));
  }

  // Angular rates at the shots: without motion the time offset cannot be seen.
  bool free_dt = options.estimate_time_offset;
  double max_rate = 0.0;
  for (std::size_t k = 0; k < fp.index.size(); ++k)
    max_rate = std::max(max_rate, fp.segments[fp.group[k]].gyro->rate(fp.photo(k).t_shot + fp.dt).norm());
  if (free_dt && rad2deg(max_rate) < options.min_rate_deg_s) {
    warn(diagnostics, warnings,
         fmt::format("time offset unobservable: the phone was still at every shot (largest rate {:.2f}°/s); δt fixed "
                     "at {} s",
                     rad2deg(max_rate), options.time_offset_start_s));
    free_dt = false;
  }

  // Closed-form start and the time-offset grid search.
  const std::size_t n = fp.index.size(), P = fp.segments.size();
  double dt0 = options.time_offset_start_s;
  std::vector<Mat3> boards;
  if (free_dt) {
    if (!(options.time_offset_max_s > options.time_offset_min_s && options.time_offset_step_s > 0))
      throw std::invalid_argument("calibrate_reference_free: empty time-offset bracket");
    double best = std::numeric_limits<double>::infinity();
    Mat3 X;
    const int steps = static_cast<int>(
        std::floor((options.time_offset_max_s - options.time_offset_min_s) / options.time_offset_step_s + 1e-9));
    for (int s = 0; s <= steps; ++s) {
      const double dt = options.time_offset_min_s + s * options.time_offset_step_s;
      const double c = fp.closed_form(dt, X, boards);
      if (c < best) best = c, dt0 = dt;
    }
  }
  if (free_dt && (dt0 <= options.time_offset_min_s + 0.5 * options.time_offset_step_s ||
                  dt0 >= options.time_offset_max_s - 0.5 * options.time_offset_step_s))
    warn(diagnostics, warnings,
         fmt::format("time offset search ended at the edge of [{}, {}] s ({} s): widen the bracket", options.time_offset_min_s,
                     options.time_offset_max_s, dt0));
  out.time_offset_grid_s = dt0;
  fp.dt = dt0;
  fp.closed_form(dt0, fp.X0, boards);
  out.R_device_camera_closed_form = fp.X0;
  for (std::size_t s = 0; s < P; ++s) fp.segments[s].B0 = boards[s];

  // Pass 1: Huber loss; flag outliers on the robustly normalised whitened residual.
  std::vector<bool> use(n, true);
  fp.solve(use, true, free_dt, false);
  std::vector<double> chi2(n), angle(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 e = fp.residual(k);
    chi2[k] = e.dot(fp.photo_covariance(k).ldlt().solve(e));
    angle[k] = e.norm();
  }
  const double scale = std::max(median(chi2) / 2.366, 1e-12);  // median of χ²₃ is 2.366
  std::size_t outliers = 0;
  for (std::size_t k = 0; k < n; ++k)
    if (chi2[k] / scale > options.outlier_chi2 && rad2deg(angle[k]) > options.min_outlier_deg) use[k] = false, ++outliers;
  if (outliers > 0)
    warn(diagnostics, warnings,
         fmt::format("{} of {} photos are outliers (residual beyond χ²₃ = {} of the robust scale); refitted without them",
                     outliers, n, options.outlier_chi2));
  if (outliers * 3 > n)
    warn(diagnostics, warnings, "more than a third of the photos are outliers: check the board detection and the track");

  // Pass 2: least squares on the inliers, covariance from Ceres scaled by the residual variance.
  // Parameters: x, and per segment a board attitude and a bias (the bias has its prior's 3 rows).
  const std::size_t params = 3 + 3 * P;
  // The gyroscope correction's 9 prior rows balance its 9 parameters, as the bias's do. When it
  // is estimated, a variance factor below 1 does not scale the covariance down: the correction
  // fits part of the photos' noise (how many of its 9 parameters the photos determine, the count
  // of degrees of freedom does not know), and the share of the covariance that its prior sets is
  // a stated budget, not a fitted noise level.
  auto final_solve = [&](bool with_dt) {
    const auto sol = fp.solve(use, false, with_dt, true);
    const double dof = 3.0 * static_cast<double>(sol.residuals) - static_cast<double>(params + (with_dt ? 1 : 0));
    out.variance_factor = dof > 0 ? 2.0 * sol.cost / dof : 1.0;
    const double scale = fp.estimate_gyro() ? std::max(1.0, out.variance_factor) : out.variance_factor;
    if (sol.cov_x) out.covariance = *sol.cov_x * scale;
    const Vec3 bias_var(std::pow(options.camera_rotation_sigma_rad.x(), 2), std::pow(options.camera_rotation_sigma_rad.y(), 2), 0.0);
    out.covariance += fp.X() * bias_var.asDiagonal() * fp.X().transpose();
    out.time_offset_estimated = with_dt;
    // A variance that could not be computed stays NaN (std::max(0.0, NaN) would make it 0).
    const auto sigma = [&](double var) {
      const double swing = sol.damped ? sol.dt_step : 0.0;
      return with_dt && var >= 0.0 ? std::sqrt(var * scale + swing * swing) : kNaN;
    };
    out.time_offset_sigma_s = sigma(sol.var_dt);
    out.time_offset_sigma_fit_s = sigma(sol.var_dt_fit);
    out.gyro_correction_estimated = fp.estimate_gyro();
    out.gyro_correction = Mat3::Identity() + fp.G;
    out.gyro_correction_sigma = (sol.var_G * scale).cwiseMax(0.0).cwiseSqrt();
    if (!sol.converged)
      warn(diagnostics, warnings, "reference-free fit: Levenberg–Marquardt stopped without convergence");
    if (!sol.settled)
      warn(diagnostics, warnings,
           fmt::format("reference-free fit: the time offset and the gyroscope's bias{} did not settle (last "
                       "time-offset step {:.3f} ms); the figures are those of the last re-linearisation",
                       fp.estimate_gyro() ? " and correction" : "", 1e3 * sol.dt_step));
  };
  final_solve(free_dt);
  if (free_dt && !(out.time_offset_sigma_s <= options.max_time_offset_sigma_s)) {
    if (fp.estimate_gyro()) refuse_offset_blurred_by_gyroscope(out, options, fp.dt);
    const std::string sigma = std::isnan(out.time_offset_sigma_s)
                                  ? std::string("σ(δt) could not be computed")
                                  : fmt::format("σ(δt) = {:.1f} ms exceeds {:.1f} ms", 1e3 * out.time_offset_sigma_s,
                                                1e3 * options.max_time_offset_sigma_s);
    warn(diagnostics, warnings,
         fmt::format("time offset unobservable: {} (too little motion at the shots); δt fixed at {} s", sigma,
                     options.time_offset_start_s));
    fp.dt = options.time_offset_start_s;
    final_solve(false);
  }
  if (out.time_offset_estimated && (fp.dt < options.time_offset_min_s || fp.dt > options.time_offset_max_s))
    warn(diagnostics, warnings,
         fmt::format("time offset {:.4f} s lies outside the searched bracket [{}, {}] s", fp.dt,
                     options.time_offset_min_s, options.time_offset_max_s));

  if (fp.estimate_gyro()) warn_uncalibrated_gyroscope(out, diagnostics);

  out.R_device_camera = fp.X();
  out.time_offset_s = fp.dt;
  // The boards in the world: chordal mean of what the orientation track implies at the inliers;
  // a photo's disagreement with that mean is the track's error there (tilt, heading).
  std::vector<std::vector<Mat3>> implied(P);
  std::vector<Mat3> R_world_board_photo(n);
  for (std::size_t k = 0; k < n; ++k) {
    R_world_board_photo[k] = device_rotation(track, fp.photo(k).t_shot + fp.dt) * out.R_device_camera *
                             fp.photo(k).R_camera_board;
    if (use[k]) implied[fp.group[k]].push_back(R_world_board_photo[k]);
  }
  std::vector<Mat3> R_world_board(P);
  for (std::size_t s = 0; s < P; ++s)
    R_world_board[s] = implied[s].empty() ? Mat3::Identity() : chordal_mean(implied[s]);
  std::vector<double> sum_sq(P, 0.0);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 e = fp.residual(k);
    const Vec3 e_world = log_so3(R_world_board_photo[k] * R_world_board[fp.group[k]].transpose());
    PhotoResidual r;
    r.photo = fp.index[k];
    r.name = describe(photos[r.photo], r.photo);
    r.placement = photos[r.photo].placement;
    r.angle_deg = rad2deg(e.norm());
    r.tilt_deg = rad2deg(e_world.head<2>().norm());
    r.heading_deg = rad2deg(e_world.z());
    r.normalised = e.dot(fp.photo_covariance(k).ldlt().solve(e)) / (out.variance_factor > 0 ? out.variance_factor : 1.0);
    r.outlier = !use[k];
    if (r.outlier) out.outliers.push_back(r.photo);
    else sum_sq[fp.group[k]] += e.squaredNorm();
    out.residuals.push_back(std::move(r));
  }
  for (std::size_t s = 0; s < P; ++s) {
    const auto& seg = fp.segments[s];
    const std::size_t count = implied[s].size();
    out.boards.push_back({seg.placement, R_world_board[s], count,
                          count ? rad2deg(std::sqrt(sum_sq[s] / static_cast<double>(count))) : kNaN, seg.bias});
  }
  if (reference)
    out.reference_check = reference_angle_errors(photos, *reference, track, out.R_device_camera, out.time_offset_s,
                                                 ThesisOptions{}, "reference-free");
  return out;
}

}  // namespace antpose::calibration
