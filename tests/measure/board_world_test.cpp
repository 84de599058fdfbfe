#include "antpose/measure/board_world.hpp"

#include <cmath>
#include <cstdio>
#include <random>

#include <Eigen/SVD>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/calibration/calibrate_imu.hpp"
#include "antpose/measure/antenna_attitude.hpp"
#include "antpose/sim/imu_simulator.hpp"

namespace antpose::measure {
namespace {

using ::testing::HasSubstr;

struct Scene {
  Mat3 R_world_board;
  CameraImu ci;
  std::vector<BoardPhoto> photos;
  orientation::OrientationTrack track;
};

// `n` photos of a board from around it; the track is the truth turned by a common heading error
// plus per-photo heading noise; PnP noise 0.05° per axis.
Scene scene(int n, double common_heading_deg, double heading_noise_deg, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  Scene s;
  s.R_world_board = exp_so3(Vec3(0.3, -0.2, 1.1));
  s.ci.R_device_camera = Vec3(1, -1, -1).asDiagonal();
  s.ci.covariance = Mat3::Identity() * std::pow(deg2rad(0.02), 2);
  s.ci.time_offset_s = 0.03;
  const double pnp = deg2rad(0.05);
  const Mat3 cov = Vec3(std::pow(deg2rad(0.3), 2), std::pow(deg2rad(0.3), 2), std::pow(deg2rad(1.0), 2)).asDiagonal();
  for (int i = 0; i < n; ++i) {
    const double t = 1.0 + i;
    // Camera 3 m from the board, around its normal (board z points into the board).
    const double a = deg2rad(-40 + 80.0 * i / std::max(1, n - 1));
    const Vec3 c_board(3 * std::sin(a), 0.5 * std::cos(3 * a), -3 * std::cos(a));
    Mat3 R_board_camera;  // camera looking at the board's origin
    const Vec3 z = (-c_board).normalized(), x = Vec3::UnitY().cross(z).normalized();
    R_board_camera << x, z.cross(x), z;
    const Mat3 R_camera_board = R_board_camera.transpose();
    const Mat3 R_world_device = s.R_world_board * R_board_camera * s.ci.R_device_camera.transpose();
    const double heading = deg2rad(common_heading_deg + heading_noise_deg * g(rng));
    for (double dt : {-0.5, 0.0, 0.5})
      s.track.push_back(t + s.ci.time_offset_s + dt, Quat(exp_so3(Vec3(0, 0, heading)) * R_world_device), cov);
    BoardPhoto p;
    p.name = "shot " + std::to_string(i);
    p.t_shot = t;
    p.R_camera_board = exp_so3(pnp * Vec3(g(rng), g(rng), g(rng))) * R_camera_board;
    p.t_camera_board = -R_camera_board * c_board;
    p.cov_R_camera_board = Mat3::Identity() * pnp * pnp;
    s.photos.push_back(p);
  }
  return s;
}

TEST(BoardWorld, MedianCarriesTheCommonHeadingErrorAndItsSigma) {
  const Scene s = scene(12, 1.0, 0.2, 1);
  Diagnostics d;
  const auto r = board_world_attitude(s.photos, s.track, s.ci, {}, d);
  const Vec3 e = log_so3(r.R_world_board * s.R_world_board.transpose());
  std::printf("error (%.3f, %.3f, %.3f)°, σ (%.3f, %.3f, %.3f)°, heading scatter %.2f°, view spread %.0f°\n",
              rad2deg(e.x()), rad2deg(e.y()), rad2deg(e.z()), rad2deg(std::sqrt(r.covariance(0, 0))),
              rad2deg(std::sqrt(r.covariance(1, 1))), rad2deg(std::sqrt(r.covariance(2, 2))), r.heading_scatter_deg,
              r.view_spread_deg);
  EXPECT_NEAR(rad2deg(e.z()), 1.0, 0.15);  // the common heading error does not average out ...
  EXPECT_LT(e.head<2>().norm(), deg2rad(0.05));
  EXPECT_NEAR(std::sqrt(r.covariance(2, 2)), deg2rad(1.0), deg2rad(0.05));  // ... and the σ says so
  EXPECT_EQ(r.used, 12u);
  EXPECT_TRUE(r.warnings.empty()) << r.warnings.front();
}

// Two of twelve photos taken while the phone still turned (heading 1.5° off, inside the outlier
// bound): the median ignores them, and so does its σ. The photos' RMS scatter over √n would make
// it 0.2°, six times the error it can have.
TEST(BoardWorld, TheMediansSigmaIgnoresThePhotosTakenInMotion) {
  Scene s = scene(12, 0.0, 0.05, 6);
  orientation::OrientationTrack track;
  for (std::size_t k = 0; k < s.track.size(); ++k) {
    Quat q = s.track.q_world_device[k];
    for (const std::size_t i : {3u, 8u})
      if (std::abs(s.track.t[k] - (s.photos[i].t_shot + s.ci.time_offset_s)) < 0.6)
        q = Quat(exp_so3(Vec3(0, 0, deg2rad(1.5))) * q.toRotationMatrix());
    track.push_back(s.track.t[k], q, s.track.covariance[k]);
  }
  BoardWorldOptions o;
  o.common_sigma_rad = Vec2::Zero();  // only what differs between photos
  Diagnostics d;
  const auto r = board_world_attitude(s.photos, track, s.ci, o, d);
  const Vec3 e = log_so3(r.R_world_board * s.R_world_board.transpose());
  const double sigma = std::sqrt(r.covariance(2, 2));
  std::printf("heading error %.3f°, σ %.3f°, scatter %.2f°\n", rad2deg(e.z()), rad2deg(sigma), r.heading_scatter_deg);
  EXPECT_EQ(r.used, 12u);
  EXPECT_GT(r.heading_scatter_deg, 0.5);
  EXPECT_LT(std::abs(e.z()), deg2rad(0.05));
  EXPECT_LT(sigma, deg2rad(0.06));
  EXPECT_LT(std::abs(e.z()), 3 * sigma);
}

TEST(BoardWorld, OutliersAndDisturbanceAndOneSidedViewsAreReported) {
  Scene s = scene(10, 0.0, 0.0, 2);
  // A photo whose phone heading was off by 8° (steel): left out, named; the median unmoved.
  const double t = s.photos[4].t_shot + s.ci.time_offset_s;
  orientation::OrientationTrack track;
  for (std::size_t k = 0; k < s.track.size(); ++k) {
    Quat q = s.track.q_world_device[k];
    if (std::abs(s.track.t[k] - t) < 0.6) q = Quat(exp_so3(Vec3(0, 0, deg2rad(8))) * q.toRotationMatrix());
    track.push_back(s.track.t[k], q, s.track.covariance[k]);
  }
  Diagnostics d;
  const auto r = board_world_attitude(s.photos, track, s.ci, {}, d);
  EXPECT_TRUE(r.photos[4].outlier);
  EXPECT_NEAR(r.photos[4].heading_deg, 8.0, 0.2);
  EXPECT_TRUE(d.mentions("1 photo(s) imply a board attitude more than 2° from the others and are left out: shot 4"));
  EXPECT_LT(rad2deg(rotation_distance(r.R_world_board, s.R_world_board)), 0.05);

  // Heading scatter of 2.5° RMS between photos (threshold 1.5°): a disturbance warning.
  const Scene noisy = scene(12, 0.0, 2.5, 3);
  BoardWorldOptions loose;
  loose.outlier_deg = 10;
  Diagnostics dn;
  const auto rn = board_world_attitude(noisy.photos, noisy.track, noisy.ci, loose, dn);
  EXPECT_GT(rn.heading_scatter_deg, 1.5);
  EXPECT_TRUE(dn.mentions("the photos disagree on the heading by"));

  // All photos from one spot (camera centre −R_cbᵀ t_cb the same): warned.
  Scene one = scene(5, 0.0, 0.0, 4);
  const Vec3 centre = -(one.photos[0].R_camera_board.transpose() * one.photos[0].t_camera_board);
  for (auto& p : one.photos) p.t_camera_board = -(p.R_camera_board * centre);
  Diagnostics d1;
  board_world_attitude(one.photos, one.track, one.ci, {}, d1);
  EXPECT_TRUE(d1.mentions("all photos were taken from nearly one direction"));

  // Photos without sensor data around them: named; too few left is an error.
  Scene late = scene(3, 0.0, 0.0, 5);
  late.photos[1].t_shot = 500.0;
  late.photos[2].t_shot = 600.0;
  Diagnostics dl;
  try {
    board_world_attitude(late.photos, late.track, late.ci, {}, dl);
    ADD_FAILURE() << "expected a MeasurementError";
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("1 photo(s) with a board pose and a phone orientation, at least 2 needed"));
  }
  EXPECT_TRUE(dl.mentions("shot 1 (t = 500.000 s) has no phone orientation (outside the sensor data); left out"));
}

// The board's heading from the compass at the photos: the track's heading error (here 1.5°) is
// gone; what stays is the board's tilt error about the field's horizontal direction times
// tan(dip), and the covariance says so.
TEST(BoardWorld, HeadingFromTheFieldAtThePhotos) {
  const double dip = deg2rad(60.0);
  const Vec3 B_world(0.0, 50.0 * std::cos(dip), -50.0 * std::sin(dip));  // magnetic north, down
  const Mat3 R_true = exp_so3(Vec3(0.3, -0.2, 1.1));
  const Vec3 delta = deg2rad(1.0) * Vec3(0.2, 0.3, 1.5);  // R_true = exp(δ) R_est
  BoardWorldAttitude board;
  board.R_world_board = exp_so3(-delta) * R_true;
  board.covariance = Vec3(std::pow(deg2rad(0.1), 2), std::pow(deg2rad(0.2), 2), std::pow(deg2rad(0.6), 2)).asDiagonal();
  // Each photo sees the true field in its own device frame and is turned into the world by the
  // board's attitude (the photos' tilts relative to the board are exact): exp(−δ) B, plus noise.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 0.01);
  std::vector<CompassPhoto> fields;
  for (int i = 0; i < 12; ++i) fields.push_back({exp_so3(-delta) * B_world + Vec3(g(rng), g(rng), g(rng))});
  CompassOptions options;
  options.calibration_sigma_rad = deg2rad(0.15);
  const auto r = heading_from_field(board, fields, std::nullopt, options);
  ASSERT_TRUE(r.compass_turn_rad);
  const Vec3 e = log_so3(R_true * r.R_world_board.transpose());
  std::printf("turn %.3f°, error (%.3f, %.3f, %.3f)°, heading σ %.3f°\n", rad2deg(*r.compass_turn_rad), rad2deg(e.x()),
              rad2deg(e.y()), rad2deg(e.z()), rad2deg(std::sqrt(r.covariance(2, 2))));
  // The tilt error about north (0.3°) turns the compass by tan(60°) · 0.3° = 0.52°.
  EXPECT_NEAR(rad2deg(e.z()), -std::tan(dip) * 0.3, 0.03);  // to first order
  EXPECT_NEAR(rad2deg(e.x()), 0.2, 0.015);                  // the tilt is the board's
  EXPECT_NEAR(rad2deg(e.y()), 0.3, 0.015);
  // Heading σ² = tan²(dip) σ_north² + σ_cal² + the photos' scatter over n (noise 0.01/25 µT ≈ 0.02°).
  const double expected = std::pow(std::tan(dip) * 0.2, 2) + std::pow(0.15, 2);
  EXPECT_GT(rad2deg(std::sqrt(r.covariance(2, 2))), std::sqrt(expected));
  EXPECT_LT(rad2deg(std::sqrt(r.covariance(2, 2))), std::sqrt(expected) + 0.01);  // the dip as measured: 60.2°
  EXPECT_NEAR(r.covariance(2, 1), -std::tan(dip) * std::pow(deg2rad(0.2), 2), 5e-7);
  EXPECT_NEAR(r.covariance(0, 0), board.covariance(0, 0), 0.01 * board.covariance(0, 0));  // turned by 1.5°

  // One field, or none with a horizontal part: the board as it was.
  const auto one = heading_from_field(board, {fields.front()}, std::nullopt, options);
  EXPECT_FALSE(one.compass_turn_rad);
  EXPECT_TRUE(one.R_world_board.isApprox(board.R_world_board));
  const auto vertical =
      heading_from_field(board, std::vector<CompassPhoto>(3, {Vec3(0, 0, -40)}), std::nullopt, options);
  EXPECT_FALSE(vertical.compass_turn_rad);
}

// The magnetometer calibration's share of the heading σ: its errors (hard iron, soft iron, the
// axes' turn against the accelerometer's) turn every photo's field, each by its own attitude. Over
// draws of the errors from the calibration's σ, the compass's turn spreads as the σ it states.
TEST(BoardWorld, TheCompasssCalibrationSigmaIsTheSpreadOfItsTurnOverTheCalibrationsErrors) {
  const double dip = deg2rad(62.0);
  const Vec3 B_world(0.0, 48.0 * std::cos(dip), -48.0 * std::sin(dip));
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> heading(0.0, 2 * M_PI), up(deg2rad(60), deg2rad(110));
  std::vector<Mat3> R_world_device;  // a phone held upright, turned round a board
  for (int i = 0; i < 12; ++i)
    R_world_device.push_back(exp_so3(Vec3(0, 0, heading(rng))) * exp_so3(Vec3(up(rng), 0, 0)));
  CompassCalibration c;
  c.soft_iron << 1.01, 0.01, -0.005, 0.01, 0.99, 0.008, -0.005, 0.008, 1.0;
  c.soft_iron /= std::cbrt(c.soft_iron.determinant());
  c.alignment = exp_so3(deg2rad(1.0) * Vec3(0.2, -0.15, 0.06));
  c.hard_iron_sigma_uT = Vec3(0.012, 0.015, 0.01);
  c.soft_iron_sigma << 3e-4, 2e-4, 2e-4, 2e-4, 3e-4, 2e-4, 2e-4, 2e-4, 3e-4;
  c.alignment_sigma_rad = deg2rad(1.0) * Vec3(0.02, 0.03, 0.025);
  const Vec3 b_true(1.5, -2.0, 2.5);
  // Each photo's raw field, and that field as a calibration off by (δb, δS, δ) turns it into the world.
  const auto photos = [&](const Vec3& db, const Mat3& dS, const Vec3& delta) {
    std::vector<CompassPhoto> p;
    for (const Mat3& R : R_world_device) {
      const Vec3 raw = (c.alignment * c.soft_iron).inverse() * R.transpose() * B_world + b_true;
      p.push_back({R * exp_so3(delta) * c.alignment * (c.soft_iron + dS) * (raw - b_true - db), R});
    }
    return p;
  };
  BoardWorldAttitude board;  // exact, so that only the calibration is left in the heading's σ
  const auto exact = heading_from_field(board, photos(Vec3::Zero(), Mat3::Zero(), Vec3::Zero()), c, {});
  ASSERT_TRUE(exact.compass_turn_rad);
  const double stated = std::sqrt(exact.covariance(2, 2));
  std::normal_distribution<double> g(0.0, 1.0);
  double sum2 = 0.0;
  const int draws = 2000;
  for (int k = 0; k < draws; ++k) {
    const Vec3 db = c.hard_iron_sigma_uT.cwiseProduct(Vec3(g(rng), g(rng), g(rng)));
    Mat3 dS;
    for (int r = 0; r < 3; ++r)
      for (int col = r; col < 3; ++col) dS(r, col) = dS(col, r) = c.soft_iron_sigma(r, col) * g(rng);
    const Vec3 delta = c.alignment_sigma_rad.cwiseProduct(Vec3(g(rng), g(rng), g(rng)));
    const double turn = *heading_from_field(board, photos(db, dS, delta), c, {}).compass_turn_rad;
    sum2 += turn * turn;
  }
  const double spread = std::sqrt(sum2 / draws);
  std::printf("stated %.4f°, spread over %d draws %.4f°\n", rad2deg(stated), draws, rad2deg(spread));
  EXPECT_NEAR(stated / spread, 1.0, 0.07);  // 2000 draws: the spread's own 1σ is 1.6 %, the σ's sampling 2 %
  // Each part alone is smaller: the hard iron's 0.015 µT over a 22.5 µT horizontal field is 0.04°.
  CompassCalibration alignment_only = c;
  alignment_only.hard_iron_sigma_uT.setZero(), alignment_only.soft_iron_sigma.setZero();
  const auto part = heading_from_field(board, photos(Vec3::Zero(), Mat3::Zero(), Vec3::Zero()), alignment_only, {});
  EXPECT_LT(part.covariance(2, 2), 0.8 * exact.covariance(2, 2));
  // Without the calibration's σ: the fallback prior.
  CompassOptions fallback;
  fallback.calibration_sigma_rad = deg2rad(0.15);
  const auto prior =
      heading_from_field(board, photos(Vec3::Zero(), Mat3::Zero(), Vec3::Zero()), std::nullopt, fallback);
  EXPECT_NEAR(rad2deg(std::sqrt(prior.covariance(2, 2))), 0.15, 1e-9);
}

// The same σ against what a calibration leaves: phones drawn within a typical phone's tolerances,
// each calibrated as `calibrate imu` does (18 held poses, then a tumble), photographed upright
// round a board. The heading the compass gives the board, against the truth, over the σ it states.
TEST(BoardWorld, ACompassCalibrationNeedsTheSigmaOfEachOfItsParameters) {
  imu::ImuCalibration imu;
  imu.mag_soft_iron = Mat3::Identity() * 1.01;
  imu.mag_hard_iron_sigma_uT = Vec3(0.1, 0.2, 0.3);
  imu.mag_soft_iron_sigma = Mat3::Constant(0.002);
  EXPECT_FALSE(compass_calibration(imu)) << "no σ of the alignment: the profile's compass σ is unknown";
  imu.mag_alignment_sigma_rad = Vec3::Constant(0.001);
  const auto c = compass_calibration(imu);
  ASSERT_TRUE(c);
  EXPECT_TRUE(c->soft_iron.isApprox(imu.mag_soft_iron));
  EXPECT_EQ(c->hard_iron_sigma_uT, *imu.mag_hard_iron_sigma_uT);
  EXPECT_EQ(c->alignment_sigma_rad, *imu.mag_alignment_sigma_rad);
}

TEST(BoardWorld, TheCompasssCalibrationSigmaCoversWhatCalibratedPhonesLeave) {
  const Vec3 B_world(0.0, 24.0, -41.569219381653056);  // the simulator's field: magnetic north, dip 60°
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> heading(0.0, 2 * M_PI), up(deg2rad(60), deg2rad(115)), roll(-0.17, 0.17);
  std::vector<double> z;
  for (int phone = 0; phone < 8; ++phone) {
    sim::ImuSimulation sim;
    sim.phone = sim::PhoneModel::random(rng);
    sim.kind = "imu-calibration";
    sim.trajectory = sim::static_poses(sim::calibration_poses(), 3.0, 2.0);
    Diagnostics d;
    calibration::CalibrateImuOptions held;
    held.magnetometer = false;
    const auto base = calibration::calibrate_imu(sim::simulate_imu(sim), held, d, "poses").calibration;
    sim.trajectory = sim::tumble(40.0, 1.5, 100 + phone);
    calibration::CalibrateImuOptions turned;
    turned.accelerometer = turned.gyroscope = false;
    const auto cal = calibration::calibrate_imu(sim::simulate_imu(sim), turned, d, "tumble", base).calibration;
    const auto compass = compass_calibration(cal);
    ASSERT_TRUE(compass);
    // The calibrated frame: the accelerometer's corrected axes (their rotation part), which the
    // camera's calibration refers to.
    const Mat3 C =
        cal.acc_correction() * sim.phone.accelerometer.misalignment * sim.phone.accelerometer.scale.asDiagonal();
    const Eigen::JacobiSVD<Mat3> svd(C, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Mat3 R_calibrated_device = svd.matrixU() * svd.matrixV().transpose();
    for (int site = 0; site < 10; ++site) {
      std::vector<CompassPhoto> photos;
      for (int i = 0; i < 12; ++i) {
        const Mat3 R_world_device =
            exp_so3(Vec3(0, 0, heading(rng))) * exp_so3(Vec3(up(rng), 0, 0)) * exp_so3(Vec3(0, roll(rng), 0));
        const Vec3 raw = sim.phone.magnetometer.apply(R_world_device.transpose() * B_world);
        const Mat3 R_world_calibrated = R_world_device * R_calibrated_device.transpose();
        photos.push_back({R_world_calibrated * cal.correct_mag(raw), R_world_calibrated});
      }
      const auto board = heading_from_field({}, photos, *compass, {});
      ASSERT_TRUE(board.compass_turn_rad);
      z.push_back(*board.compass_turn_rad / std::sqrt(board.covariance(2, 2)));
    }
  }
  double sum2 = 0.0, largest = 0.0;
  for (double v : z) sum2 += v * v, largest = std::max(largest, std::abs(v));
  const double rms = std::sqrt(sum2 / static_cast<double>(z.size()));
  std::printf("RMS(error/σ) %.2f over %zu phone-sites, largest |error/σ| %.2f\n", rms, z.size(), largest);
  EXPECT_GT(rms, 0.6);
  EXPECT_LT(rms, 1.5);
  EXPECT_LT(largest, 4.0);
}

TEST(AntennaAttitude, ComposesBoardAndRegistrationWithTrueNorth) {
  const Scene s = scene(8, 0.0, 0.0, 6);
  Diagnostics d;
  const auto board = board_world_attitude(s.photos, s.track, s.ci, {}, d);
  const Mat3 R_world_antenna = rotation_from_attitude(deg2rad(123.0), deg2rad(6.0), deg2rad(-1.0));
  const Mat3 R_board_antenna = s.R_world_board.transpose() * R_world_antenna;
  const Mat3 cov_reg = Mat3::Identity() * std::pow(deg2rad(0.05), 2);
  geomag::SiteField site;
  site.declination = deg2rad(-6.0);
  site.declination_sigma = deg2rad(0.35);
  const auto r = antenna_attitude(board, R_board_antenna, {{"registration", cov_reg}}, site);
  ASSERT_TRUE(r.magnetic.azimuth && r.azimuth_true && r.sigma.azimuth);
  EXPECT_NEAR(rad2deg(*r.magnetic.azimuth), 123.0, 0.1);
  EXPECT_NEAR(rad2deg(r.magnetic.downtilt), 6.0, 0.05);
  EXPECT_NEAR(rad2deg(*r.magnetic.roll), -1.0, 0.05);
  EXPECT_NEAR(rad2deg(*r.azimuth_true), 117.0, 0.1);
  EXPECT_NEAR(*r.azimuth_true_sigma, std::hypot(*r.sigma.azimuth, deg2rad(0.35)), 1e-12);
  // The board's heading σ (1°) dominates the azimuth; downtilt is set by tilt σ (0.3°) and registration.
  EXPECT_NEAR(rad2deg(*r.sigma.azimuth), 1.0, 0.1);
  EXPECT_LT(rad2deg(r.sigma.downtilt), 0.4);
}

}  // namespace
}  // namespace antpose::measure
