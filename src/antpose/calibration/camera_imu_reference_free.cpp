// Method B of camera_imu.hpp: the reference-free calibration (placements, preintegrated
// gyroscope, hand–eye start, Ceres refinement, covariance, time offset).
#include "antpose/calibration/camera_imu.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <ceres/normal_prior.h>
#include <ceres/ceres.h>
#include <ceres/rotation.h>
#include <fmt/format.h>

#include "antpose/calibration/camera_imu_photos.hpp"
#include "antpose/calibration/least_squares.hpp"
#include "antpose/camera/camera_model.hpp"
#include "antpose/core/statistics.hpp"
#include "antpose/orientation/gyro_integration.hpp"

namespace antpose::calibration {

using detail::describe;
using detail::device_rotation;
using detail::kNaN;
using detail::photos_in_track;
using detail::warn;

namespace {

/// One placement's photos and the gyroscope integrated across them.
struct Segment {
  std::string placement;
  std::vector<std::size_t> members;                  // positions in FreeProblem::index
  std::optional<orientation::GyroIntegration> gyro;  // device(t) → device(t0), current bias
  Vec3 bias = Vec3::Zero();                          // accumulated bias correction (rad/s)
  std::array<double, 3> db{0, 0, 0};                 // its increment in the current linearisation
  Mat3 B0 = Mat3::Identity();                        // R_gyro_board (gyro frame = device at t0)
  std::array<double, 3> b{0, 0, 0};                  // board perturbation, gyro frame
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

/// A prior on a total correction, value + δ, element by element: (value + δ) / σ, as ceres's
/// NormalPrior A (δ − b) with A = diag(1/σ) and b = −value.
ceres::CostFunction* total_correction_prior(const ceres::Vector& value, const ceres::Vector& inv_sigma) {
  return new ceres::NormalPrior(ceres::Matrix(inv_sigma.asDiagonal()), -value);
}

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
    return R_gc * cov_c * R_gc.transpose() + Mat3::Identity() * (walk + std::pow(deg2rad(o.sigma_floor_deg), 2));
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
          problem.AddResidualBlock(total_correction_prior(seg.bias, Vec3::Constant(inv_sigma_b)), nullptr,
                                   seg.db.data());
      if (estimate_gyro()) {
        Mat3 inv_sigma = Mat3::Constant(1.0 / options->gyro_cross_axis_sigma);
        inv_sigma.diagonal().setConstant(1.0 / options->gyro_scale_sigma);
        // δG is stored row-major (dg[3r + c]), as is the transposed column-major view below.
        const Mat3 G_t = G.transpose(), inv_sigma_t = inv_sigma.transpose();
        problem.AddResidualBlock(
            total_correction_prior(ceres::Vector::Map(G_t.data(), 9), ceres::Vector::Map(inv_sigma_t.data(), 9)),
            nullptr, dg.data());
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

/// χ²/dof of a solution's whitened residuals (3 per photo) with `params` parameters fitted; 1
/// where there are no degrees of freedom left.
double variance_factor_of(const FreeProblem::Solution& sol, std::size_t params) {
  const double dof = 3.0 * static_cast<double>(sol.residuals) - static_cast<double>(params);
  return dof > 0 ? 2.0 * sol.cost / dof : 1.0;
}

/// The test of a time offset given as fixed (ReferenceFreeOptions::max_fixed_offset_z): the fit is
/// repeated with δt free, from the fixed value, and where the photos put δt further from it than
/// that many σ (σ scaled by the refit's variance factor where above 1), the fixed value is
/// refused: the rotation fitted under it absorbs the timing error as a bias its σ does not cover.
void refuse_contradicted_offset(const FreeProblem& fp, const std::vector<bool>& use,
                                const ReferenceFreeOptions& options) {
  FreeProblem probe = fp;
  const auto sol = probe.solve(use, false, true, true);
  const double variance_factor = variance_factor_of(sol, 4 + 3 * fp.segments.size());
  if (!(sol.var_dt > 0)) return;
  const double sigma = std::sqrt(sol.var_dt * std::max(1.0, variance_factor));
  const double z = std::abs(probe.dt - fp.dt) / sigma;
  if (!(z > options.max_fixed_offset_z)) return;
  throw MeasurementError(fmt::format(
      "camera–IMU calibration: the time offset held fixed at {:.1f} ms contradicts the photos, which put it at "
      "{:.1f} ± {:.1f} ms ({:.0f} σ away): a rotation fitted with the fixed value would carry the difference as an "
      "error its σ does not cover; let the offset be estimated, or give the right one",
      1e3 * fp.dt, 1e3 * probe.dt, 1e3 * sigma, z));
}

/// χ² test of the fit (ReferenceFreeOptions::max_variance_factor): a model that leaves residuals
/// several times the photos' expected noise is refused, whatever σ its scaled covariance gives.
void refuse_misfit(const ReferenceFreeCalibration& out, const ReferenceFreeOptions& options, double dt) {
  if (!(out.variance_factor > options.max_variance_factor)) return;
  const std::string cause =
      out.time_offset_estimated
          ? "a board moved within a placement, a gap or a jump in the gyroscope's log, or photos whose time stamps "
            "are not the shutter's"
          : fmt::format(
                "the time offset held fixed at {:.1f} ms is likely wrong: let it be estimated, or give the "
                "right one",
                1e3 * dt);
  throw MeasurementError(fmt::format(
      "camera–IMU calibration: the photos' residuals are {:.1f} times their expected noise (χ²/dof {:.1f}, at most "
      "{:.0f} accepted), so the rotation and time offset do not describe them: {}",
      std::sqrt(out.variance_factor), out.variance_factor, options.max_variance_factor, cause));
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

OptionProblems ReferenceFreeOptions::Check() const {
  OptionProblems p;
  const auto finite = [](std::initializer_list<double> values) {
    return std::all_of(values.begin(), values.end(), [](double v) { return std::isfinite(v); });
  };
  p.require(finite({time_offset_min_s, time_offset_max_s}) && time_offset_min_s < time_offset_max_s,
            "time_offset_min_s, time_offset_max_s", "finite, min < max");
  p.require(std::isfinite(time_offset_start_s) && time_offset_start_s >= time_offset_min_s &&
                time_offset_start_s <= time_offset_max_s,
            "time_offset_start_s", "finite, within [time_offset_min_s, time_offset_max_s]");
  p.require(time_offset_step_s > 0.0 && max_time_offset_sigma_s > 0.0, "time_offset_step_s, max_time_offset_sigma_s",
            "positive");
  p.require(gyro_bias_sigma_rad_s > 0.0 && std::isfinite(gyro_bias_sigma_rad_s), "gyro_bias_sigma_rad_s",
            "positive, finite");
  p.require(std::isfinite(gyro_scale_sigma) && std::isfinite(gyro_cross_axis_sigma) &&
                ((gyro_scale_sigma == 0.0 && gyro_cross_axis_sigma == 0.0) ||
                 (gyro_scale_sigma > 0.0 && gyro_cross_axis_sigma > 0.0)),
            "gyro_scale_sigma, gyro_cross_axis_sigma", "both 0 or both positive");
  p.require(finite({min_rate_deg_s, min_view_change_deg, min_axis_spread_deg, gyro_noise_density, max_gyro_gap_s,
                    default_pnp_sigma_deg, sigma_floor_deg, huber_k, outlier_chi2, min_outlier_deg, max_variance_factor,
                    max_fixed_offset_z}) &&
                camera_rotation_sigma_rad.allFinite(),
            "thresholds and noise levels", "finite");
  p.require(min_photos_per_placement >= 2 && max_iterations >= 1, "min_photos_per_placement, max_iterations",
            "at least 2 and 1");
  return p;
}

ReferenceFreeCalibration calibrate_reference_free(const std::vector<PhotoObservation>& photos,
                                                  const orientation::SensorSeries& gyroscope,
                                                  const orientation::OrientationTrack& track,
                                                  const ReferenceFreeOptions& options, Diagnostics& diagnostics,
                                                  const BoardReference* reference) {
  ReferenceFreeCalibration out;
  auto& warnings = out.warnings;
  if (gyroscope.size() < 2)
    throw MeasurementError("camera–IMU calibration: the gyroscope stream has fewer than 2 samples");
  throw_unless_ok(options.Check(), "ReferenceFreeOptions");
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
    throw MeasurementError(
        fmt::format("camera–IMU calibration: no usable placement ({} photos given, {} inside the "
                    "orientation track; see the warnings)",
                    photos.size(), usable.size()));

  // Observability of the rotation: the relative camera rotations must not all share one axis.
  {
    Mat3 S = Mat3::Zero();
    std::size_t pairs = 0;
    for (std::size_t i = 0; i < fp.index.size(); ++i)
      for (std::size_t j = i + 1; j < fp.index.size(); ++j)
        if (fp.group[i] == fp.group[j]) {
          const Vec3 beta =
              log_so3(photos[fp.index[i]].R_camera_board * photos[fp.index[j]].R_camera_board.transpose());
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
         fmt::format("time offset search ended at the edge of [{}, {}] s ({} s): widen the bracket",
                     options.time_offset_min_s, options.time_offset_max_s, dt0));
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
    if (chi2[k] / scale > options.outlier_chi2 && rad2deg(angle[k]) > options.min_outlier_deg)
      use[k] = false, ++outliers;
  if (outliers > 0)
    warn(diagnostics, warnings,
         fmt::format(
             "{} of {} photos are outliers (residual beyond χ²₃ = {} of the robust scale); refitted without them",
             outliers, n, options.outlier_chi2));
  if (outliers * 3 > n)
    warn(diagnostics, warnings,
         "more than a third of the photos are outliers: check the board detection and the track");

  // Pass 2: least squares on the inliers, covariance from Ceres scaled by the residual variance.
  // Parameters: x, and per segment a board attitude and a bias (the bias has its prior's 3 rows).
  const std::size_t params = 3 + 3 * P;
  // The gyroscope correction's 9 prior rows balance its 9 parameters, as the bias's do. The
  // covariance is scaled by the variance factor only from above (the Birge ratio): residuals
  // smaller than the photos' stated noise do not show that the rotation is better known, since
  // what is common to all photos (the intrinsics, the IMU calibration's axes, the rendering or
  // the lens) leaves no residual; and an estimated gyroscope correction fits part of the noise
  // besides (how many of its 9 parameters the photos determine, the count of degrees of freedom
  // does not know).
  auto final_solve = [&](bool with_dt) {
    const auto sol = fp.solve(use, false, with_dt, true);
    out.variance_factor = variance_factor_of(sol, params + (with_dt ? 1 : 0));
    const double scale = std::max(1.0, out.variance_factor);
    if (sol.cov_x) out.covariance = *sol.cov_x * scale;
    const Vec3 bias_var(std::pow(options.camera_rotation_sigma_rad.x(), 2),
                        std::pow(options.camera_rotation_sigma_rad.y(), 2), 0.0);
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
  if (!options.estimate_time_offset && rad2deg(max_rate) >= options.min_rate_deg_s)
    refuse_contradicted_offset(fp, use, options);
  refuse_misfit(out, options, fp.dt);
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
    R_world_board_photo[k] =
        device_rotation(track, fp.photo(k).t_shot + fp.dt) * out.R_device_camera * fp.photo(k).R_camera_board;
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
    r.normalised =
        e.dot(fp.photo_covariance(k).ldlt().solve(e)) / (out.variance_factor > 0 ? out.variance_factor : 1.0);
    r.outlier = !use[k];
    if (r.outlier)
      out.outliers.push_back(r.photo);
    else
      sum_sq[fp.group[k]] += e.squaredNorm();
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
