#include "antpose/imu/hard_iron.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/QR>

#include <fmt/core.h>

namespace antpose::imu {

HardIronEstimate estimate_hard_iron(const Stream& magnetometer, const HardIronOptions& options,
                                    const std::filesystem::path& source) {
  const std::string where = source.empty() ? std::string("magnetometer stream") : source.string();
  if (!magnetometer.has_xyz() || magnetometer.size() < options.min_samples)
    throw MeasurementError(fmt::format(
        "{}: hard-iron calibration needs at least {} magnetometer samples with x, y, z columns (has {})", where,
        options.min_samples, magnetometer.size()));

  HardIronEstimate out;
  out.samples = magnetometer.size();
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = -lo;
  for (std::size_t i = 0; i < magnetometer.size(); ++i) {
    const Vec3 m = magnetometer.xyz(i);
    lo = lo.cwiseMin(m);
    hi = hi.cwiseMax(m);
  }
  out.hard_iron_uT = (hi + lo) / 2.0;
  out.range_uT = hi - lo;
  double sum = 0.0, sum2 = 0.0;
  for (std::size_t i = 0; i < magnetometer.size(); ++i) {
    const double r = (magnetometer.xyz(i) - out.hard_iron_uT).norm();
    sum += r;
    sum2 += r * r;
  }
  const double n = static_cast<double>(magnetometer.size());
  out.field_uT = sum / n;
  out.radius_spread = out.field_uT > 0.0 ? std::sqrt(std::max(0.0, sum2 / n - out.field_uT * out.field_uT)) / out.field_uT
                                         : std::numeric_limits<double>::infinity();
  Eigen::MatrixX4d A(magnetometer.size(), 4);
  Eigen::VectorXd y(magnetometer.size());
  for (std::size_t i = 0; i < magnetometer.size(); ++i) {
    const Vec3 m = magnetometer.xyz(i);
    A.row(static_cast<Eigen::Index>(i)) << 2.0 * m.transpose(), 1.0;
    y(static_cast<Eigen::Index>(i)) = m.squaredNorm();
  }
  out.sphere_center_uT = A.colPivHouseholderQr().solve(y).head<3>();
  out.residual_uT = (out.hard_iron_uT - out.sphere_center_uT).norm();
  out.coverage = out.field_uT > 0.0 ? Vec3(out.range_uT / (2.0 * out.field_uT)) : Vec3::Zero();

  // A sweep that covers only part of the sphere can still give a large range/|B| ratio when
  // |B| is taken from the (wrong) centre; the spread of |m − b| and a minimum field catch it.
  if (out.coverage.minCoeff() < options.min_coverage || out.radius_spread > options.max_radius_spread ||
      out.field_uT < options.min_field_uT) {
    static constexpr char kAxis[] = {'x', 'y', 'z'};
    std::string detail;
    for (int k = 0; k < 3; ++k)
      detail += fmt::format("{}{}: range {:.1f} µT = {:.0f}%", k ? ", " : "", kAxis[k], out.range_uT[k],
                            100.0 * out.coverage[k]);
    throw MeasurementError(fmt::format(
        "{}: the phone was not turned enough for a hard-iron calibration: each magnetometer axis must sweep at "
        "least {:.0f}% of 2|B| = {:.1f} µT ({}), and |m − b| must stay constant within {:.0f}% (it varies by "
        "{:.0f}%) and exceed {:.0f} µT; record again turning the phone slowly through all directions "
        "(figure-eight, every face up and down)",
        where, 100.0 * options.min_coverage, 2.0 * out.field_uT, detail, 100.0 * options.max_radius_spread,
        100.0 * std::min(out.radius_spread, 9.99), options.min_field_uT));
  }
  return out;
}

}  // namespace antpose::imu
