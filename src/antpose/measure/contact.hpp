// Contact measurement (thesis §7.2): the phone is pressed with its back flat on the antenna's
// back plate; its static orientation is the plate's.
//
//   longest static window (imu/static_detector) → static orientation R_world_device, world =
//   ENU magnetic (orientation/static_orientation) → R_world_antenna = R_world_device ·
//   R_device_antenna(placement) → azimuth (magnetic), downtilt, roll (geometry/attitude) →
//   true azimuth = magnetic + declination (WMM at the capture's site).
//
// Uncertainties (1σ) propagate the static orientation's tilt σ_t and heading σ_h:
//   downtilt σ_t;  roll σ_t / cos(downtilt) (the in-plane gravity component shrinks with tilt);
//   magnetic azimuth sqrt(σ_h² + (σ_t tan(downtilt))²);
//   true azimuth adds the WMM2025 declination error model in quadrature:
//   σ_D = sqrt(0.26² + (5417 nT / H)²) degrees (WMM2025 technical report, error model;
//   ≈ 0.3–0.4° at mid latitudes).
// Warnings (strings in the result, never silent): magnetic disturbance (field magnitude or dip
// far from the WMM at the site, or outside 25–65 µT without a site), short window, phone
// moved or not flat (block scatter), plate horizontal (implausible for a panel), boresight
// vertical (azimuth and roll undefined), large uncertainty.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "antpose/geometry/attitude.hpp"
#include "antpose/imu/hard_iron.hpp"
#include "antpose/imu/imu_calibration.hpp"
#include "antpose/imu/static_detector.hpp"
#include "antpose/orientation/static_orientation.hpp"

namespace antpose::measure {

struct ContactOptions {
  ContactPlacement placement = ContactPlacement::kTopUp;
  std::optional<imu::ImuCalibration> calibration;  // applied to the streams before anything else
  imu::StaticDetectorParams detector;
  orientation::StaticOrientationOptions orientation;  // floors for a calibrated sensor
  // Floors used instead for a sensor the calibration does not cover: a factory-calibrated
  // phone accelerometer keeps a zero-g offset of tens of mg (BMI160 datasheet: ±40 mg; 8 mg
  // 1σ after the maker's trim), an OS-calibrated magnetometer a residual hard iron of a few µT.
  double uncalibrated_acc_bias_mps2 = 0.08;
  double uncalibrated_mag_residual_uT = 4.0;
  double min_window_s = 2.0;                  // a shorter longest static window is warned about
  double trim_s = 0.25;                       // dropped at both ends of the window (the phone settling),
                                              // only when at least min_window_s remains
  double field_tolerance = 0.10;              // |F − F_wmm| / F_wmm above this: disturbance
  double dip_tolerance = deg2rad(5.0);        // |dip − I_wmm| above this: disturbance
  double plausible_field_min_uT = 25.0;       // band used without a site
  double plausible_field_max_uT = 65.0;
  double max_block_tilt = deg2rad(0.5);       // phone moved during the window
  double max_block_heading = deg2rad(3.0);
  double horizontal_plate_limit = deg2rad(20.0);  // boresight this close to vertical: implausible
  double uncertain_azimuth = deg2rad(3.0);    // 1σ above these: "uncertain" warning
  double uncertain_tilt = deg2rad(0.5);
};

struct ContactUncertainty {
  double azimuth = 0.0;                 // rad, magnetic azimuth, 1σ
  std::optional<double> azimuth_true;   // rad, including the declination's uncertainty
  double downtilt = 0.0;
  double roll = 0.0;
  std::optional<double> declination;
};

struct ContactResult {
  ContactPlacement placement = ContactPlacement::kTopUp;
  double t0 = 0.0, t1 = 0.0;             // static window used, s
  std::optional<double> azimuth_magnetic;  // rad, [0, 2π); empty when the boresight is vertical
  std::optional<double> azimuth_true;      // rad, [0, 2π); needs a site
  std::optional<double> declination;       // rad, positive east; needs a site
  double downtilt = 0.0;                   // rad
  std::optional<double> roll;              // rad
  ContactUncertainty sigma;
  Mat3 R_world_antenna_magnetic = Mat3::Identity();  // world = ENU, magnetic north

  double field_uT = 0.0;                   // measured |B|
  double dip = 0.0;                        // rad, measured, positive down
  std::optional<double> expected_field_uT; // WMM F at the site
  std::optional<double> expected_dip;      // WMM inclination, rad
  bool magnetic_disturbance = false;

  orientation::StaticOrientation phone;    // the phone's static orientation (thesis angles inside)
  std::size_t static_windows = 0;          // how many static intervals the detector found
  std::vector<std::string> warnings;
};

/// The contact measurement of `capture` (see the file comment). Throws InputError when the
/// accelerometer or magnetometer stream is missing, MeasurementError when no static window
/// is found or the field gives no heading.
ContactResult measure_contact(const Capture& capture, const ContactOptions& options = {});

/// Calibrates the magnetometer from `recording` (the phone turned in all directions) with the
/// thesis's hard iron (max+min)/2 and sets it as `options.calibration`; the estimate's residual
/// (distance to the least-squares sphere centre) raises the heading-error floor, so that a
/// sweep that missed an axis's extremes does not give a confident azimuth. Throws
/// MeasurementError when the recording does not cover enough directions.
imu::HardIronEstimate calibrate_from_recording(const Capture& recording, ContactOptions& options);

/// JSON report: azimuth_magnetic_deg, azimuth_true_deg, declination_deg, downtilt_deg,
/// roll_deg, sigma {azimuth_magnetic_deg, azimuth_true_deg, downtilt_deg, roll_deg}, warnings,
/// window_s, field {measured_uT, expected_uT, dip_deg, expected_dip_deg}, placement,
/// phone_attitude {yaw_deg, pitch_deg, roll_deg}. Undefined values are null.
nlohmann::json to_json(const ContactResult& result);

}  // namespace antpose::measure
