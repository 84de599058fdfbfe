#include "antpose/measure/antenna_attitude.hpp"

#include <algorithm>
#include <cmath>

namespace antpose::measure {

AntennaAttitudeResult antenna_attitude(const BoardWorldAttitude& board, const Mat3& R_board_antenna,
                                       const std::vector<UncertaintySource>& sources_board,
                                       const std::optional<geomag::SiteField>& site) {
  AntennaAttitudeResult r;
  r.R_world_antenna = board.R_world_board * R_board_antenna;
  r.covariance = board.covariance;
  r.budget.push_back({kBoardAttitudeSource, attitude_sigma(r.R_world_antenna, board.covariance)});
  for (const auto& part : sources_board) {
    const Mat3 world = board.R_world_board * part.covariance * board.R_world_board.transpose();
    r.covariance += world;
    r.budget.push_back({part.source, attitude_sigma(r.R_world_antenna, world)});
  }
  r.magnetic = attitude_from_rotation(r.R_world_antenna);
  r.sigma = attitude_sigma(r.R_world_antenna, r.covariance);
  r.warnings = board.warnings;
  if (!r.magnetic.azimuth)
    r.warnings.push_back("the boresight is within 1° of vertical: azimuth and roll are undefined");
  if (site && r.magnetic.azimuth) {
    r.azimuth_true = wrap_2pi(*r.magnetic.azimuth + site->declination);
    r.azimuth_true_sigma = std::hypot(*r.sigma.azimuth, site->declination_sigma);
  }
  return r;
}

double widen_for_rivals(AntennaAttitudeResult& at, const Mat3& R_result, const std::vector<Mat3>& rivals_board,
                        const BoardWorldAttitude& board, const std::string& source) {
  const auto widen = [](auto& sigma, double difference) {
    if (sigma) sigma = std::hypot(*sigma, difference / 2);
  };
  const AttitudeSigma before = at.sigma;
  double turn = 0.0;
  for (const Mat3& R : rivals_board) {
    turn = std::max(turn, angle_between(R.col(1), R_result.col(1)));
    // The rival's boresight in the result's frame, as a turn about the result's long axis.
    const Vec3 boresight = R_result.transpose() * R.col(1);
    const Mat3 R_about_axis =
        R_result * Eigen::AngleAxisd(std::atan2(-boresight.x(), boresight.y()), Vec3::UnitZ()).toRotationMatrix();
    double d_azimuth = 0.0, d_downtilt = 0.0, d_roll = 0.0;
    for (const Mat3& R_other : {R, R_about_axis}) {
      const auto other = attitude_from_rotation(board.R_world_board * R_other);
      if (at.magnetic.azimuth && other.azimuth)
        d_azimuth = std::max(d_azimuth, std::abs(wrap_pi(*other.azimuth - *at.magnetic.azimuth)));
      d_downtilt = std::max(d_downtilt, std::abs(other.downtilt - at.magnetic.downtilt));
      if (at.magnetic.roll && other.roll) d_roll = std::max(d_roll, std::abs(wrap_pi(*other.roll - *at.magnetic.roll)));
    }
    widen(at.sigma.azimuth, d_azimuth);
    widen(at.azimuth_true_sigma, d_azimuth);
    at.sigma.downtilt = std::hypot(at.sigma.downtilt, d_downtilt / 2);
    widen(at.sigma.roll, d_roll);
  }
  if (!rivals_board.empty()) {
    // The widening's own share: what it added in quadrature.
    const auto added = [](double now, double was) { return std::sqrt(std::max(0.0, now * now - was * was)); };
    const auto added_to = [&](const std::optional<double>& now, const std::optional<double>& was) {
      return now && was ? std::optional<double>(added(*now, *was)) : std::nullopt;
    };
    at.budget.push_back({source,
                         {added_to(at.sigma.azimuth, before.azimuth), added(at.sigma.downtilt, before.downtilt),
                          added_to(at.sigma.roll, before.roll)}});
  }
  return turn;
}

}  // namespace antpose::measure
