#include "antpose/measure/board_world.hpp"

#include <algorithm>
#include <cmath>
#include <random>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>

#include "antpose/camera/board_pose.hpp"
#include "antpose/core/statistics.hpp"
#include "antpose/geometry/symmetric3.hpp"

namespace antpose::measure {
namespace {

void warn(Diagnostics& d, std::vector<std::string>& warnings, std::string message) {
  warnings.push_back(message);
  d.warn(std::move(message));
}

/// Covariance of the track at t (world): the options' calibrated model when set, else the
/// track's own, else a generic phone's when the track has none.
Mat3 track_covariance(const orientation::OrientationTrack& track, double t, const BoardWorldOptions& options) {
  if (options.common_sigma_rad) {
    const double tilt = options.common_sigma_rad->x(), heading = options.common_sigma_rad->y();
    return Vec3(tilt * tilt, tilt * tilt, heading * heading).asDiagonal();
  }
  const auto s = track.at(t);
  if (s.covariance && s.covariance->allFinite() && s.covariance->trace() > 0.0) return *s.covariance;
  const double tilt = deg2rad(0.5), heading = deg2rad(3.0);
  return Vec3(tilt * tilt, tilt * tilt, heading * heading).asDiagonal();
}

// The covariance of the L1 median of n rotations from their residuals about it (rad², the
// residuals' frame): each axis's robust scale (the photos taken while the phone still moved carry
// outsized errors that the median ignores and an RMS would count in full), over n, times the
// spatial median's variance factor in three dimensions against the mean's, 1.18 (its efficiency
// 0.849 for Gaussian data; Brown, "Statistical uses of the spatial median", JRSS B 45, 1983).
Mat3 l1_median_covariance(const std::vector<Vec3>& residuals) {
  if (residuals.size() < 2) return Mat3::Zero();
  const auto n = static_cast<double>(residuals.size());
  Vec3 variance = Vec3::Zero();
  for (int a = 0; a < 3; ++a) {
    std::vector<double> axis;
    for (const Vec3& v : residuals) axis.push_back(v[a]);
    variance[a] = 1.18 * std::pow(robust_sigma(std::move(axis)), 2) / n;
  }
  return variance.asDiagonal();
}

}  // namespace

Mat3 l1_rotation_median(const std::vector<Mat3>& rotations, int max_iterations) {
  Mat3 R = chordal_mean(rotations);
  for (int it = 0; it < max_iterations; ++it) {
    Vec3 num = Vec3::Zero();
    double den = 0.0;
    for (const auto& Ri : rotations) {
      const Vec3 v = log_so3(Ri * R.transpose());
      const double w = 1.0 / std::max(v.norm(), 1e-9);  // Weiszfeld: inverse distance
      num += w * v, den += w;
    }
    const Vec3 step = num / den;
    R = exp_so3(step) * R;
    if (step.norm() < 1e-12) break;
  }
  return R;
}

BoardWorldAttitude board_world_attitude(const std::vector<BoardPhoto>& photos,
                                        const orientation::OrientationTrack& track, const CameraImu& ci,
                                        const BoardWorldOptions& o, Diagnostics& diagnostics) {
  BoardWorldAttitude out;
  std::vector<std::size_t> inside;
  std::vector<Mat3> R_wb(photos.size()), R_wd(photos.size());
  for (std::size_t i = 0; i < photos.size(); ++i) {
    out.photos.push_back({photos[i].name, 0, 0, 0, true});
    const double t = photos[i].t_shot + ci.time_offset_s;
    if (!track.contains(t)) {
      warn(diagnostics, out.warnings,
           fmt::format("{} (t = {:.3f} s) has no phone orientation (outside the sensor data); left out", photos[i].name,
                       photos[i].t_shot));
      continue;
    }
    R_wd[i] = track.at(t).q_world_device.toRotationMatrix();
    R_wb[i] = R_wd[i] * ci.R_device_camera * photos[i].R_camera_board;
    inside.push_back(i);
  }
  if (inside.size() < o.min_photos)
    throw MeasurementError(
        fmt::format("board attitude in the world: {} photo(s) with a board pose and a phone "
                    "orientation, at least {} needed",
                    inside.size(), o.min_photos));

  // Median, outliers, median again without them.
  std::vector<Mat3> all;
  for (std::size_t i : inside) all.push_back(R_wb[i]);
  const Mat3 first = l1_rotation_median(all, o.max_iterations);
  std::vector<std::size_t> used;
  std::vector<std::string> outliers;
  for (std::size_t i : inside) {
    if (rad2deg(rotation_distance(R_wb[i], first)) > o.outlier_deg)
      outliers.push_back(photos[i].name);
    else
      used.push_back(i);
  }
  if (used.size() < o.min_photos)
    throw MeasurementError(
        fmt::format("board attitude in the world: the photos disagree by more than {}° (outliers: "
                    "{}); check the board detection and the phone's orientation",
                    o.outlier_deg, fmt::join(outliers, ", ")));
  if (!outliers.empty())
    warn(diagnostics, out.warnings,
         fmt::format("{} photo(s) imply a board attitude more than {}° from the others and are left out: {}",
                     outliers.size(), o.outlier_deg, fmt::join(outliers, ", ")));
  std::vector<Mat3> kept;
  for (std::size_t i : used) kept.push_back(R_wb[i]);
  out.R_world_board = l1_rotation_median(kept, o.max_iterations);
  out.used = used.size();

  // Residuals and the photos' scatter.
  const double n = static_cast<double>(used.size());
  Mat3 common = Mat3::Zero(), pnp = Mat3::Zero();
  std::vector<Vec3> residuals;
  double heading_sq = 0.0;
  for (std::size_t i : inside) {
    const Vec3 v = log_so3(R_wb[i] * out.R_world_board.transpose());
    auto& r = out.photos[i];
    r.angle_deg = rad2deg(v.norm());
    r.tilt_deg = rad2deg(v.head<2>().norm());
    r.heading_deg = rad2deg(v.z());
    r.outlier = std::find(used.begin(), used.end(), i) == used.end();
    if (r.outlier) continue;
    residuals.push_back(v);
    heading_sq += v.z() * v.z() / n;
    const double t = photos[i].t_shot + ci.time_offset_s;
    common += (track_covariance(track, t, o) + R_wd[i] * ci.covariance * R_wd[i].transpose()) / n;
    const Mat3 R_wc = R_wd[i] * ci.R_device_camera;
    pnp += R_wc * photos[i].cov_R_camera_board * R_wc.transpose() / (n * n);
  }
  out.heading_scatter_deg = rad2deg(std::sqrt(heading_sq));
  const Mat3 scatter_of_median = l1_median_covariance(residuals);
  out.covariance = common + (scatter_of_median.trace() > pnp.trace() ? scatter_of_median : pnp);

  if (out.heading_scatter_deg > o.heading_scatter_warn_deg)
    warn(diagnostics, out.warnings,
         fmt::format("the photos disagree on the heading by {:.1f}° RMS (more than {}°): the magnetometer was probably "
                     "disturbed near the mast; the azimuth is uncertain",
                     out.heading_scatter_deg, o.heading_scatter_warn_deg));
  // Where the cameras were, seen from the board: camera centre in the board frame, −R_cbᵀ t_cb.
  for (std::size_t a = 0; a < used.size(); ++a)
    for (std::size_t b = a + 1; b < used.size(); ++b) {
      const Vec3 ca = camera::camera_centre(photos[used[a]].R_camera_board, photos[used[a]].t_camera_board);
      const Vec3 cb = camera::camera_centre(photos[used[b]].R_camera_board, photos[used[b]].t_camera_board);
      if (ca.norm() > 0 && cb.norm() > 0)
        out.view_spread_deg = std::max(out.view_spread_deg, rad2deg(angle_between(ca, cb)));
    }
  if (out.view_spread_deg < o.min_view_spread_deg)
    warn(diagnostics, out.warnings,
         fmt::format("all photos were taken from nearly one direction (largest angle between two views {:.1f}°, less "
                     "than {}°): the reconstruction's depth and the registration are weak; walk around",
                     out.view_spread_deg, o.min_view_spread_deg));
  return out;
}

std::optional<CompassCalibration> compass_calibration(const imu::ImuCalibration& calibration) {
  if (!calibration.mag_hard_iron_sigma_uT || !calibration.mag_soft_iron_sigma || !calibration.mag_alignment_sigma_rad)
    return std::nullopt;
  return CompassCalibration{calibration.mag_soft_iron, calibration.mag_alignment, *calibration.mag_hard_iron_sigma_uT,
                            *calibration.mag_soft_iron_sigma, *calibration.mag_alignment_sigma_rad};
}

namespace {

// σ_cal (heading_from_field). Each photo's heading change is linear in the calibration's errors
// e = (δb, the 6 entries of δS, δ), row g_i; the compass takes their median, which is not linear
// in e (the photo in the middle changes with e's direction), so its spread is sampled over draws
// of e: a fixed generator, so that a capture's σ is reproducible; 1000 draws leave it within
// about 2 %. `photos`: at least one, each field with a horizontal part (heading_from_field's).
double compass_calibration_sigma(const std::vector<CompassPhoto>& photos, const CompassCalibration& c) {
  using Row = Eigen::Matrix<double, 1, 12>;
  const Mat3 unwarp = (c.alignment * c.soft_iron).inverse();
  std::vector<Row> g;
  for (const auto& p : photos) {
    const Vec3& b = p.field_world_uT;
    const double h2 = b.head<2>().squaredNorm();
    const Eigen::RowVector3d dpsi = Eigen::RowVector3d(b.y() / h2, -b.x() / h2, 0.0) * p.R_world_device;
    const Vec3 m = p.R_world_device.transpose() * b, u = unwarp * m;
    Row row;
    row.head<3>() = dpsi * (-c.alignment * c.soft_iron);
    for (int k = 0; k < 6; ++k) {
      Mat3 E = Mat3::Zero();
      const auto [r, col] = kSymmetricEntries[k];
      E(r, col) = E(col, r) = 1.0;
      row(3 + k) = dpsi * (c.alignment * E * u);
    }
    row.tail<3>() = dpsi * (-skew(m));
    g.push_back(row);
  }
  Eigen::Matrix<double, 12, 1> sigma;
  sigma.head<3>() = c.hard_iron_sigma_uT;
  for (int k = 0; k < 6; ++k) sigma(3 + k) = c.soft_iron_sigma(kSymmetricEntries[k].row, kSymmetricEntries[k].col);
  sigma.tail<3>() = c.alignment_sigma_rad;
  std::mt19937_64 rng(1);
  std::normal_distribution<double> unit(0.0, 1.0);
  constexpr int kDraws = 1000;
  double sum2 = 0.0;
  std::vector<double> turns(g.size());
  for (int k = 0; k < kDraws; ++k) {
    Eigen::Matrix<double, 12, 1> e;
    for (int i = 0; i < 12; ++i) e(i) = sigma(i) * unit(rng);
    for (std::size_t i = 0; i < g.size(); ++i) turns[i] = g[i] * e;
    const double m = median(turns);
    sum2 += m * m;
  }
  return std::sqrt(sum2 / kDraws);
}

}  // namespace

BoardWorldAttitude heading_from_field(BoardWorldAttitude board, const std::vector<CompassPhoto>& photos,
                                      const std::optional<CompassCalibration>& calibration, const CompassOptions& o) {
  std::vector<double> east_of_north;  // rad, clockwise from +y
  std::vector<CompassPhoto> used;
  Vec3 mean = Vec3::Zero();
  for (const auto& p : photos)
    if (const Vec3& b = p.field_world_uT; b.head<2>().norm() > 1e-6 * b.norm()) {
      east_of_north.push_back(std::atan2(b.x(), b.y()));
      mean += b / b.norm();
      used.push_back(p);
    }
  const auto n = east_of_north.size();
  if (n < o.min_photos || n == 0) return board;
  // Angles relative to the first, so that a field near south does not wrap.
  for (double& a : east_of_north) a = east_of_north.front() + wrap_pi(a - east_of_north.front());
  const double turn = median(east_of_north);  // counter-clockwise: brings the field to +y
  // The median's standard error: the robust scale times √(π/2) (its efficiency 2/π for Gaussian
  // data), over √n.
  std::vector<double> residuals;
  for (const double a : east_of_north) residuals.push_back(wrap_pi(a - turn));
  const double scatter_of_median =
      n > 1 ? robust_sigma(std::move(residuals)) * std::sqrt(M_PI / 2 / static_cast<double>(n)) : 0.0;
  const double calibration_sigma =
      calibration ? compass_calibration_sigma(used, *calibration) : o.calibration_sigma_rad;

  const Mat3 R_turn = exp_so3(Vec3(0.0, 0.0, turn));
  const Vec3 b = R_turn * mean;
  const double tan_dip = -b.z() / b.head<2>().norm();
  const Vec3 h = Vec3(b.x(), b.y(), 0.0).normalized();
  Mat3 A = Mat3::Identity();
  A.row(2) = -tan_dip * h.transpose();
  board.R_world_board = R_turn * board.R_world_board;
  const Mat3 turned = R_turn * board.covariance * R_turn.transpose();
  board.covariance = A * turned * A.transpose();
  board.covariance(2, 2) += calibration_sigma * calibration_sigma + scatter_of_median * scatter_of_median;
  board.compass_turn_rad = turn;
  return board;
}

}  // namespace antpose::measure
