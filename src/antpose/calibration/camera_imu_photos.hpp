// The photos both camera–IMU methods share (camera_imu.hpp): their names in messages, the phone's
// attitude at their shots, and which of them the orientation track covers.
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "antpose/calibration/camera_imu.hpp"

namespace antpose::calibration::detail {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A warning kept with the result and reported through `diagnostics`.
void warn(Diagnostics& diagnostics, std::vector<std::string>& warnings, std::string message);

/// The photo's name, else "photo <index>".
std::string describe(const PhotoObservation& p, std::size_t index);

/// R_world_device at `t`, clamped into the track's span (used only for the small excursions of a
/// time-offset search: photos outside the span are rejected before).
Mat3 device_rotation(const orientation::OrientationTrack& track, double t);

struct UsablePhoto {
  std::size_t index;
  Mat3 R_world_device;
};

/// Photos inside the track (others warned about and left out), at IMU time t_shot + dt.
/// MeasurementError for an empty track or a photo without a finite shot time and rotation.
std::vector<UsablePhoto> photos_in_track(const std::vector<PhotoObservation>& photos,
                                         const orientation::OrientationTrack& track, double dt,
                                         Diagnostics& diagnostics, std::vector<std::string>* warnings);

}  // namespace antpose::calibration::detail
