#include "antpose/measure/antenna_attitude.hpp"

#include <cmath>

namespace antpose::measure {

AntennaAttitudeResult antenna_attitude(const BoardWorldAttitude& board, const Mat3& R_board_antenna,
                                       const Mat3& cov_board, const std::optional<geomag::SiteField>& site) {
  AntennaAttitudeResult r;
  r.R_world_antenna = board.R_world_board * R_board_antenna;
  r.covariance = board.covariance + board.R_world_board * cov_board * board.R_world_board.transpose();
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

}  // namespace antpose::measure
