#include "antpose/calibration/accelerometer.hpp"
#include "antpose/calibration/least_squares.hpp"

#include <cmath>

#include <ceres/ceres.h>
#include <Eigen/Dense>
#include <fmt/format.h>

namespace antpose::calibration {
namespace {

struct GravityResidual {
  explicit GravityResidual(const Vec3& y, double g) : y_(y), g_(g) {}
  template <typename T>
  bool operator()(const T* const p, T* r) const {
    // p = (t01, t02, t12, k0, k1, k2, b0, b1, b2)
    const T u0 = p[3] * (T(y_[0]) - p[6]);
    const T u1 = p[4] * (T(y_[1]) - p[7]);
    const T u2 = p[5] * (T(y_[2]) - p[8]);
    const T a0 = u0 + p[0] * u1 + p[1] * u2;
    const T a1 = u1 + p[2] * u2;
    const T a2 = u2;
    r[0] = ceres::sqrt(a0 * a0 + a1 * a1 + a2 * a2) - T(g_);
    return true;
  }
  Vec3 y_;
  double g_;
};

void require_frames(std::size_t have, std::size_t need, const char* what, const std::string& source) {
  if (have < need)
    throw MeasurementError(fmt::format(
        "{}{}accelerometer calibration ({}): found {} static frame{}, need at least {}; record the device still in "
        "at least {} different orientations (each axis up and down, then tilted), about 2 s each",
        source, source.empty() ? "" : ": ", what, have, have == 1 ? "" : "s", need, need));
}

}  // namespace

std::pair<double, double> gravity_residual(const AccelerometerCalibration& c, const std::vector<Vec3>& means) {
  double ss = 0.0, mx = 0.0;
  for (const auto& y : means) {
    const double r = c.correct(y).norm() - c.gravity;
    ss += r * r;
    mx = std::max(mx, std::abs(r));
  }
  return {means.empty() ? 0.0 : std::sqrt(ss / static_cast<double>(means.size())), mx};
}

AccelerometerCalibration fit_accelerometer_thesis(const std::vector<Vec3>& means, double g, const std::string& source) {
  require_frames(means.size(), 6, "thesis normalization, 6 unknowns", source);
  const auto n = static_cast<Eigen::Index>(means.size());
  Eigen::MatrixXd A(n, 6);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3& y = means[static_cast<std::size_t>(i)];
    A.row(i) << y.x() * y.x(), y.y() * y.y(), y.z() * y.z(), y.x(), y.y(), y.z();
  }
  const Eigen::VectorXd ones = Eigen::VectorXd::Ones(n);
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
  if (qr.rank() < 6)
    throw MeasurementError(fmt::format("{}{}accelerometer calibration: the {} static frames do not span enough "
                                       "orientations (rank {} of 6); turn each axis up and down",
                                       source, source.empty() ? "" : ": ", means.size(), qr.rank()));
  const Eigen::VectorXd th = qr.solve(ones);
  AccelerometerCalibration c;
  c.method = "thesis";
  c.gravity = g;
  c.frames = means.size();
  for (int k = 0; k < 3; ++k) {
    if (!(th[k] > 0.0))
      throw MeasurementError(fmt::format("{}{}accelerometer calibration: the static frames do not lie on an "
                                         "ellipsoid (axis {} coefficient {:.3g}); the device moved during the "
                                         "'static' frames or the poses are too few",
                                         source, source.empty() ? "" : ": ", "xyz"[k], th[k]));
    c.bias[k] = -th[3 + k] / (2.0 * th[k]);
  }
  double sab = 0.0;
  for (int k = 0; k < 3; ++k) sab += th[k] * c.bias[k] * c.bias[k];
  const double G = g * g / (1.0 + sab);
  for (int k = 0; k < 3; ++k) c.scale[k] = std::sqrt(th[k] * G);
  double ss = 0.0;
  for (const auto& y : means) ss += std::pow(y.norm() - g, 2);
  c.rms_before = std::sqrt(ss / static_cast<double>(means.size()));
  std::tie(c.rms_after, c.max_after) = gravity_residual(c, means);
  return c;
}

AccelerometerCalibration fit_accelerometer_full(const std::vector<Vec3>& means, double g,
                                                const AccelerometerCalibration& start, const std::string& source) {
  require_frames(means.size(), 9, "9-parameter model", source);
  double p[9] = {start.misalignment(0, 1), start.misalignment(0, 2), start.misalignment(1, 2),
                 start.scale[0], start.scale[1], start.scale[2], start.bias[0], start.bias[1], start.bias[2]};
  ceres::Problem problem;
  for (const auto& y : means)
    problem.AddResidualBlock(new ceres::AutoDiffCostFunction<GravityResidual, 1, 9>(new GravityResidual(y, g)), nullptr, p);
  const ceres::Solver::Summary summary = solve_levenberg_marquardt(problem, 200, 1e-14);
  if (!summary.IsSolutionUsable())
    throw MeasurementError(fmt::format("{}{}accelerometer 9-parameter fit failed: {}", source, source.empty() ? "" : ": ",
                                       summary.message));
  AccelerometerCalibration c;
  c.method = "full";
  c.gravity = g;
  c.frames = means.size();
  c.misalignment(0, 1) = p[0];
  c.misalignment(0, 2) = p[1];
  c.misalignment(1, 2) = p[2];
  c.scale = Vec3(p[3], p[4], p[5]);
  c.bias = Vec3(p[6], p[7], p[8]);
  c.rms_before = start.rms_before;
  std::tie(c.rms_after, c.max_after) = gravity_residual(c, means);
  if (means.size() > 9)
    parameter_sigmas(problem, p, summary.final_cost, static_cast<double>(means.size() - 9), c.sigma);
  return c;
}

void canonical_accelerometer(const Mat3& C, Mat3& T, Vec3& k, Mat3* rotation) {
  const Eigen::HouseholderQR<Mat3> qr(C);
  Mat3 Q = qr.householderQ();
  Mat3 U = qr.matrixQR().triangularView<Eigen::Upper>();
  // Make U's diagonal positive (Q U = (Q D)(D U) with D = diag(±1)).
  for (int i = 0; i < 3; ++i)
    if (U(i, i) < 0) {
      U.row(i) *= -1.0;
      Q.col(i) *= -1.0;
    }
  k = U.diagonal();
  T = U * k.cwiseInverse().asDiagonal();
  if (rotation) *rotation = Q;
}

}  // namespace antpose::calibration
