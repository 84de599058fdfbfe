#include "antpose/measure/time_offset.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

namespace antpose::measure {
namespace {

// RMS angle of the photos' board attitudes about their L1 median at offset δ; nullopt where fewer
// than `min_photos` instants lie inside the track.
std::optional<double> spread_at(double offset_s, const std::vector<BoardPhoto>& photos,
                                const orientation::OrientationTrack& track, const Mat3& R_device_camera,
                                std::size_t min_photos) {
  std::vector<Mat3> R_world_board;
  for (const auto& p : photos)
    if (const double t = p.t_shot + offset_s; track.contains(t))
      R_world_board.push_back(track.at(t).q_world_device.toRotationMatrix() * R_device_camera * p.R_camera_board);
  if (R_world_board.size() < min_photos) return std::nullopt;
  const Mat3 median = l1_rotation_median(R_world_board);
  double sum = 0.0;
  for (const Mat3& R : R_world_board) sum += std::pow(rotation_distance(R, median), 2);
  return std::sqrt(sum / static_cast<double>(R_world_board.size()));
}

}  // namespace

OptionProblems TimeOffsetOptions::Check() const {
  OptionProblems p;
  p.require(search_s > 0 && search_s <= 2.0, "search_s", "in (0, 2] s");
  p.require(step_s > 0 && step_s <= search_s, "step_s", "in (0, search_s]");
  p.require(tolerance_floor_rad >= 0, "tolerance_floor_rad", "≥ 0");
  p.require(tolerance_share >= 0, "tolerance_share", "≥ 0");
  p.require(min_photos >= 2, "min_photos", "at least 2");
  return p;
}

TimeOffsetCheck check_time_offset(const std::vector<BoardPhoto>& photos, const orientation::OrientationTrack& track,
                                  const CameraImu& camera_imu, const TimeOffsetOptions& options) {
  throw_unless_ok(options.Check(), "TimeOffsetOptions");
  TimeOffsetCheck out;
  out.device_s = out.used_s = camera_imu.time_offset_s;
  if (!options.enabled) return out;
  const auto at_device = spread_at(out.device_s, photos, track, camera_imu.R_device_camera, options.min_photos);
  if (!at_device) return out;
  const int n = static_cast<int>(std::round(options.search_s / options.step_s));
  std::vector<double> offsets, spreads;
  for (int k = -n; k <= n; ++k) {
    const double offset = out.device_s + k * options.step_s;
    if (const auto s = spread_at(offset, photos, track, camera_imu.R_device_camera, options.min_photos))
      offsets.push_back(offset), spreads.push_back(*s);
  }
  const auto least = std::min_element(spreads.begin(), spreads.end()) - spreads.begin();
  out.checked = true;
  out.least_spread_rad = spreads[least];
  out.spread_at_device_rad = *at_device;
  const double limit =
      out.least_spread_rad + std::max(options.tolerance_floor_rad, options.tolerance_share * out.least_spread_rad);
  // The consistent range about the least spread: the offsets next to it within the limit.
  auto lo = least, hi = least;
  while (lo > 0 && spreads[lo - 1] <= limit) --lo;
  while (hi + 1 < static_cast<std::ptrdiff_t>(spreads.size()) && spreads[hi + 1] <= limit) ++hi;
  out.consistent_low_s = offsets[lo], out.consistent_high_s = offsets[hi];
  out.device_consistent = *at_device <= limit;
  if (out.device_consistent) return out;
  out.used_s = 0.5 * (out.consistent_low_s + out.consistent_high_s);
  out.warnings.push_back(fmt::format(
      "the photos' time stamps disagree with the device's camera–IMU offset ({:+.0f} ms): with it the photos' board "
      "attitudes spread by {:.2f}° RMS, with {:+.0f} to {:+.0f} ms by {:.2f}°; {:+.0f} ms is used (this capture's "
      "photo clock differs from the calibration's)",
      1e3 * out.device_s, rad2deg(out.spread_at_device_rad), 1e3 * out.consistent_low_s, 1e3 * out.consistent_high_s,
      rad2deg(out.least_spread_rad), 1e3 * out.used_s));
  return out;
}

}  // namespace antpose::measure
