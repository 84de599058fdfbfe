// Magnetometer hard iron from a calibration recording (thesis §4.4): while the phone is turned
// in all directions, each axis sees the Earth field from +|B| to −|B| plus the constant
// offset b of the phone's own magnetised parts, so b_k = (max_k + min_k) / 2 per device axis.
// The estimate is only meaningful when every axis has actually been swept: we require each
// axis range (max_k − min_k) to reach `min_coverage` · 2|B|, with |B| the mean magnitude of
// the corrected samples, and the corrected samples to lie on a sphere (|m − b| constant within
// max_radius_spread), which a partial sweep does not. Soft iron (an ellipsoid instead of a
// sphere) is not estimated.
//
// (max+min)/2 rests on the extreme samples only: an axis whose extremes were missed by a few
// percent shifts the centre by as much. As a check, the centre is also fitted to all samples
// as a sphere (linear least squares on |m|² = 2 m·c + r² − |c|², e.g. Vasconcelos et al.,
// IEEE Trans. Magn. 47(2), 2011, eq. 7 with S = I); the distance between the two centres is
// reported as the estimate's residual, which contact mode uses as its heading-error floor.
#pragma once

#include <cstddef>
#include <filesystem>

#include "antpose/io/capture.hpp"

namespace antpose::imu {

struct HardIronOptions {
  double min_coverage = 0.7;        // each axis range ≥ this fraction of 2|B|
  double max_radius_spread = 0.15;  // std(|m − b|) / mean(|m − b|): the samples must lie on a sphere
  double min_field_uT = 10.0;       // mean |m − b| below this is no Earth field (the phone was still)
  std::size_t min_samples = 20;
};

struct HardIronEstimate {
  Vec3 hard_iron_uT = Vec3::Zero();  // device frame, µT; subtract from the raw field
  Vec3 range_uT = Vec3::Zero();      // max − min per axis
  double field_uT = 0.0;             // mean |m − b|
  Vec3 coverage = Vec3::Zero();      // range_k / (2 field_uT)
  double radius_spread = 0.0;        // std(|m − b|) / field_uT (soft iron and noise; ≈ 0.06 for 10 % soft iron)
  Vec3 sphere_center_uT = Vec3::Zero();  // least-squares sphere centre (the cross-check)
  double residual_uT = 0.0;          // |hard_iron − sphere_center|: how far the estimate can be trusted
  std::size_t samples = 0;
};

/// (max + min)/2 per axis of a magnetometer stream (µT, device frame). Throws
/// MeasurementError naming `source` when the stream has too few samples or an axis was not
/// swept far enough (the message gives each axis's coverage and says how to record).
HardIronEstimate estimate_hard_iron(const Stream& magnetometer, const HardIronOptions& options = {},
                                    const std::filesystem::path& source = {});

}  // namespace antpose::imu
