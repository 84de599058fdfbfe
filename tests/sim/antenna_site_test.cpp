// The wide distribution of antenna sites: over many seeds every drawn parameter stays in its
// range and the ranges are covered (uptilt and downtilt, both arrangements, every radome, light
// and background, close pairs, 2 and 12 MP photos); fixes force their case; drawn layouts never
// intersect; and a rendered low-resolution site has its ROI around the panel and photos of the
// resized camera.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "antpose/sim/antenna_capture.hpp"
#include "antpose/sim/antenna_mounts.hpp"
#include "antpose/sim/antenna_site.hpp"
#include "antpose/sim/capture_geometry.hpp"
#include "antpose/sim/capture_simulator.hpp"
#include "sim/truth_yaml.hpp"
#include "support/test_support.hpp"

namespace antpose::sim {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A 12 MP phone (4000 × 3000 native) of the device seed.
camera::CameraIntrinsics native_12mp(std::uint64_t device_seed) {
  DeviceOptions o;
  o.width = 4000, o.height = 3000;
  return make_device(o, device_seed).intrinsics;
}

WideSiteOptions options_for(std::uint64_t seed) {
  WideSiteOptions o;
  o.setting = seed % 2 == 0 ? AntennaSetting::kRooftop : AntennaSetting::kGround;
  o.antennas = 1 + static_cast<int>(seed / 2 % 3);
  o.photos = 12;
  o.native = native_12mp(401);
  return o;
}

// Smallest angle between two azimuths, deg.
double azimuth_gap_deg(double a, double b) { return std::abs(rad2deg(wrap_pi(a - b))); }

// The ranges of one drawn site (docs/simulator.md, wide distribution).
void expect_in_ranges(const SiteDraw& s, const WideSiteOptions& o) {
  const bool roof = o.setting == AntennaSetting::kRooftop;
  const double mp = s.photo.camera.width * static_cast<double>(s.photo.camera.height) / 1e6;
  EXPECT_GE(mp, 2.0 - 0.01);
  EXPECT_LE(mp, 12.0 + 0.01);
  EXPECT_EQ(s.photo.camera.width, std::lround(4000 * s.photo.scale));
  EXPECT_NEAR(s.photo.camera.fx, o.native.fx * s.photo.camera.width / 4000.0, 1e-9);
  EXPECT_NEAR(s.photo.camera.cx, (o.native.cx + 0.5) * s.photo.camera.width / 4000.0 - 0.5, 1e-9);
  EXPECT_EQ(s.photo.camera.distortion, o.native.distortion);
  EXPECT_TRUE(s.photo.jpeg_quality >= 75 && s.photo.jpeg_quality <= 95);
  EXPECT_TRUE(s.photo.blur_sigma_px >= 0.4 && s.photo.blur_sigma_px <= 1.2);
  EXPECT_TRUE(s.photo.noise_scale >= 0.7 && s.photo.noise_scale <= 2.0);
  EXPECT_TRUE(s.photo.exposure_s >= 0.001 && s.photo.exposure_s <= 0.008);
  EXPECT_TRUE(std::abs(s.time_offset_s) <= 0.15);

  const SiteLight& L = s.light;
  const double elevation = rad2deg(L.sun_elevation);
  const bool low = L.mode == LightMode::kLowSun;
  EXPECT_TRUE(low ? elevation >= 5.0 && elevation <= 20.0 : elevation >= 25.0 && elevation <= 70.0) << elevation;
  const double a = L.ambient, d = L.direct;
  switch (L.mode) {
    case LightMode::kSun:
    case LightMode::kLowSun:
      EXPECT_TRUE(d >= 0.5 && d <= 0.75 && a >= 0.25 && a <= 0.45) << a << " " << d;
      break;
    case LightMode::kOvercast:
      EXPECT_TRUE(d >= 0.0 && d <= 0.08 && a >= 0.85 && a <= 1.0) << a << " " << d;
      break;
    case LightMode::kShade:
      EXPECT_TRUE(d == 0.0 && a >= 0.35 && a <= 0.6) << a;
      break;
  }
  for (const double sky : {L.sky_zenith, L.sky_horizon}) EXPECT_TRUE(sky >= 0.6 && sky <= 1.0);
  EXPECT_TRUE(L.cloud_contrast == 0.0 || (L.cloud_contrast >= 0.015 && L.cloud_contrast <= 0.05));
  EXPECT_TRUE(L.gain >= 0.6 && L.gain <= 0.95);

  const AntennaLayout& lay = s.layout;
  EXPECT_FALSE(layout_collides(lay, 0.01, 0.3));
  EXPECT_TRUE(roof ? lay.mast_radius_m >= 0.03 && lay.mast_radius_m <= 0.08
                   : lay.mast_radius_m >= 0.2 && lay.mast_radius_m <= 0.45);
  EXPECT_TRUE(lay.metal_albedo >= 0.35 && lay.metal_albedo <= 0.55);
  ASSERT_EQ(lay.antennas.size(), static_cast<std::size_t>(o.antennas));
  for (const SimAntenna& ant : lay.antennas) {
    const model::PanelSpec& p = ant.spec;
    const model::AntennaModel m = model::builtin_panel(ant.model_name);
    EXPECT_NEAR((m.size_m - Vec3(p.width_m, p.depth_m, p.height_m)).norm(), 0.0, 1e-12) << ant.model_name;
    EXPECT_TRUE(p.height_m >= 0.6 && p.height_m <= 2.7 && p.width_m >= 0.2 && p.width_m <= 0.5) << ant.model_name;
    EXPECT_TRUE(p.depth_m >= 0.1 && p.depth_m <= 0.25 && p.depth_m <= 0.9 * p.width_m + 1e-12) << ant.model_name;
    EXPECT_TRUE(p.edge_radius_m >= 0.0 && p.edge_radius_m <= 0.045 && p.edge_radius_m < 0.5 * std::min(p.width_m, p.depth_m));
    EXPECT_TRUE(p.bracket_width_m >= 0.06 && p.bracket_width_m <= 0.16);
    EXPECT_TRUE(p.bracket_depth_m >= 0.04 && p.bracket_depth_m <= 0.10);
    EXPECT_TRUE(p.bracket_height_m >= 0.08 && p.bracket_height_m <= 0.20);
    EXPECT_TRUE(p.bracket_end_fraction >= 0.15 && p.bracket_end_fraction <= 0.30);
    EXPECT_TRUE(ant.finish.end_cap_thickness_m >= 0.0 && ant.finish.end_cap_thickness_m <= 0.008);
    EXPECT_NO_THROW(model::parametric_panel(p));
    const double albedo = ant.finish.radome_albedo;
    constexpr std::array<double, 5> kColours{0.85, 0.7, 0.65, 0.5, 0.3};
    EXPECT_TRUE(std::any_of(kColours.begin(), kColours.end(), [&](double c) { return std::abs(albedo - c) <= 0.03 + 1e-12; }))
        << albedo;
    EXPECT_EQ(ant.finish.look, lay.antennas.front().finish.look);
    EXPECT_TRUE(rad2deg(ant.downtilt) >= -10.0 && rad2deg(ant.downtilt) <= 15.0);
    EXPECT_TRUE(std::abs(rad2deg(ant.roll)) <= 5.0);
    const double z = ant.p_world_antenna.z();
    EXPECT_TRUE(roof ? z >= 1.45 && z <= 4.05 : z >= 8.0 && z <= 30.0) << z;
    if (lay.arrangement == Arrangement::kSectors) {
      EXPECT_TRUE(ant.arm_m >= 0.08 && ant.arm_m <= 0.5);
    }
  }
  for (std::size_t j = 0; j < lay.antennas.size(); ++j)
    for (std::size_t k = j + 1; k < lay.antennas.size(); ++k) {
      const SimAntenna &p = lay.antennas[j], &q = lay.antennas[k];
      const double gap = azimuth_gap_deg(p.azimuth_magnetic, q.azimuth_magnetic);
      if (lay.arrangement == Arrangement::kSideBySide) {
        EXPECT_LE(gap, 10.0 + 1e-9);
        const Vec3 d3 = p.p_world_antenna - q.p_world_antenna;
        EXPECT_GE(std::hypot(d3.x(), d3.y()), 0.5 * (p.spec.width_m + q.spec.width_m));
      } else {
        // ~120° (or 180° for a pair) apart, ±15° each.
        EXPECT_TRUE(gap >= 90.0 - 1e-9) << gap;
      }
    }
  EXPECT_EQ(lay.arrangement == Arrangement::kSideBySide, !lay.frame.empty());

  const WalkDraw& w = s.walk;
  EXPECT_TRUE(w.target_width_px >= 60.0 && w.target_width_px <= 400.0);
  EXPECT_TRUE(roof ? w.distance_m >= 3.0 && w.distance_m <= 20.0 : w.distance_m >= 10.0 && w.distance_m <= 60.0);
  // The distance gives antenna 1 its target width at the walk's middle.
  const Vec3 C = walk_middle(w);
  const SimAntenna& a1 = lay.antennas.front();
  EXPECT_NEAR(s.photo.camera.fx * a1.spec.width_m / (C - a1.p_world_antenna).norm(), w.target_width_px, 1e-6);
  EXPECT_TRUE(w.board_max_m >= 3.5 && w.board_max_m <= 6.0);
  ASSERT_EQ(w.holds_s.size(), 12u);
  for (std::size_t k = 0; k < 12; ++k) {
    EXPECT_TRUE(w.holds_s[k] >= 0.3 && w.holds_s[k] <= 2.0);
    EXPECT_TRUE(w.instants[k] >= 0.15 && w.instants[k] <= 0.85);
  }
  EXPECT_TRUE(w.walk_speed_m_s >= 0.5 && w.walk_speed_m_s <= 1.3);
  EXPECT_TRUE(w.bob.frequency_hz >= 1.6 && w.bob.frequency_hz <= 2.2);
  EXPECT_TRUE(w.bob.amplitude_m >= 0.01 && w.bob.amplitude_m <= 0.03);
  EXPECT_TRUE(w.tremor_deg >= 0.03 && w.tremor_deg <= 0.15);
  for (const RoiDraw& r : s.roi)
    for (const double m : r.margin_fraction) EXPECT_TRUE(m >= 0.03 && m <= 0.15);

  // The background behind the mast: within ±70° of the direction away from the walk.
  const double away = std::atan2(-C.x(), -C.y());
  for (const Building& b : s.background.buildings) {
    EXPECT_LE(azimuth_gap_deg(std::atan2(b.centre_xy.x(), b.centre_xy.y()), away), 70.0 + 1e-9);
    EXPECT_GE(b.centre_xy.norm(), 25.0);
    EXPECT_TRUE(b.height_m >= 10.0 && b.height_m <= 60.0);
  }
  for (const Tree& t : s.background.trees) {
    EXPECT_LE(azimuth_gap_deg(std::atan2(t.base.x(), t.base.y()), away), 70.0 + 1e-9);
    EXPECT_TRUE(t.height_m >= 6.0 && t.height_m <= 20.0);
    if (!roof) {
      EXPECT_TRUE(t.base.head<2>().norm() >= 10.0 && t.base.head<2>().norm() <= 40.0);
    }
  }
}

TEST(SimWideSite, DrawsStayInTheirRangesAndCoverThem) {
  std::set<int> arrangements, looks, lights, backgrounds;
  double mp_min = 1e9, mp_max = 0, tilt_min = 1e9, tilt_max = -1e9, width_min = 1e9, width_max = 0;
  double closest_pair = 1e9;
  int offsets_negative = 0;
  for (std::uint64_t seed = 1; seed <= 200; ++seed) {
    const WideSiteOptions o = options_for(seed);
    const SiteDraw s = draw_wide_site(seed, o);
    SCOPED_TRACE(seed);
    expect_in_ranges(s, o);
    arrangements.insert(static_cast<int>(s.layout.arrangement));
    looks.insert(static_cast<int>(s.layout.antennas.front().finish.look));
    lights.insert(static_cast<int>(s.light.mode));
    backgrounds.insert(static_cast<int>(s.background.kind));
    const double mp = s.photo.camera.width * static_cast<double>(s.photo.camera.height) / 1e6;
    mp_min = std::min(mp_min, mp), mp_max = std::max(mp_max, mp);
    for (const auto& a : s.layout.antennas)
      tilt_min = std::min(tilt_min, rad2deg(a.downtilt)), tilt_max = std::max(tilt_max, rad2deg(a.downtilt));
    width_min = std::min(width_min, s.walk.target_width_px), width_max = std::max(width_max, s.walk.target_width_px);
    if (s.layout.arrangement == Arrangement::kSideBySide)
      for (std::size_t k = 1; k < s.layout.antennas.size(); ++k) {
        const Vec3 d = s.layout.antennas[k].p_world_antenna - s.layout.antennas[k - 1].p_world_antenna;
        closest_pair = std::min(closest_pair, std::hypot(d.x(), d.y()));
      }
    offsets_negative += s.time_offset_s < 0 ? 1 : 0;
  }
  std::printf("200 sites: %.2f-%.2f MP, downtilt %.1f..%.1f deg, antenna 1 %.0f-%.0f px wide, closest pair %.2f m\n",
              mp_min, mp_max, tilt_min, tilt_max, width_min, width_max, closest_pair);
  EXPECT_EQ(arrangements.size(), 2u);
  EXPECT_EQ(looks.size(), 3u);
  EXPECT_EQ(lights.size(), 4u);
  EXPECT_EQ(backgrounds.size(), 3u);
  EXPECT_LT(mp_min, 3.0);
  EXPECT_GT(mp_max, 11.0);
  EXPECT_LT(tilt_min, -5.0);  // uptilt
  EXPECT_GT(tilt_max, 10.0);
  // Widths above ~200 px need a wide panel close by in a large photo: rooftop sites only (on the
  // ground, 10 m away and 8 m up, a 0.5 m panel spans at most ~140 px at 12 MP).
  EXPECT_LT(width_min, 80.0);
  EXPECT_GT(width_max, 200.0);
  EXPECT_LE(closest_pair, 0.5);
  EXPECT_GT(offsets_negative, 40);
  EXPECT_LT(offsets_negative, 160);
}

TEST(SimWideSite, FixesForceTheirCase) {
  WideSiteOptions o = options_for(2);
  o.antennas = 2;
  o.fixes.photo_scale = 0.5;
  o.fixes.arrangement = Arrangement::kSideBySide;
  o.fixes.radome = RadomeLook::kRibbed;
  o.fixes.background = BackgroundKind::kTrees;
  o.fixes.light = LightMode::kOvercast;
  o.fixes.board_max_distance_m = 5.0;
  o.fixes.time_offset_s = -0.1;
  o.fixes.jpeg_quality = 60;
  o.fixes.blur_sigma_px = 0.0, o.fixes.noise_scale = 0.0, o.fixes.exposure_s = 0.0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const SiteDraw s = draw_wide_site(seed, o);
    EXPECT_EQ(s.photo.scale, 0.5);
    EXPECT_EQ(s.photo.camera.width, 2000);
    EXPECT_EQ(s.layout.arrangement, Arrangement::kSideBySide);
    for (const auto& a : s.layout.antennas) EXPECT_EQ(a.finish.look, RadomeLook::kRibbed);
    EXPECT_EQ(s.background.kind, BackgroundKind::kTrees);
    EXPECT_FALSE(s.background.trees.empty());  // rooftop: only crowns that show above the parapet
    EXPECT_EQ(s.light.mode, LightMode::kOvercast);
    EXPECT_EQ(s.walk.board_max_m, 5.0);
    EXPECT_EQ(s.time_offset_s, -0.1);
    EXPECT_EQ(s.photo.jpeg_quality, 60);
    EXPECT_EQ(s.photo.noise_scale, 0.0);
  }
  // The same seed draws the same site; another attempt another one.
  EXPECT_EQ(draw_wide_site(9, o).walk.distance_m, draw_wide_site(9, o).walk.distance_m);
  EXPECT_NE(draw_wide_site(9, o, 1).walk.distance_m, draw_wide_site(9, o).walk.distance_m);
  o.fixes.photo_scale = 0.2;
  EXPECT_THAT(test::input_error([&] { draw_wide_site(1, o); }), HasSubstr("--photo-scale"));
}

TEST(SimWideSite, BoxesIntersectOnlyWhenTheyOverlap) {
  OrientedBox a{Vec3::Zero(), Mat3::Identity(), Vec3(0.5, 0.5, 0.5)};
  OrientedBox b{Vec3(1.05, 0, 0), Mat3::Identity(), Vec3(0.5, 0.5, 0.5)};
  EXPECT_FALSE(boxes_intersect(a, b, 0.01));
  EXPECT_TRUE(boxes_intersect(a, b, 0.1));  // closer than the clearance
  // Turned 45° about z: its corner reaches 0.707 towards a.
  b.axes = rot_z(deg2rad(45.0));
  b.centre = Vec3(1.2, 0, 0);
  EXPECT_TRUE(boxes_intersect(a, b, 0.0));
  b.centre = Vec3(1.25, 0, 0);
  EXPECT_FALSE(boxes_intersect(a, b, 0.0));
  // Edge against edge: only a cross-product axis separates them.
  OrientedBox c{Vec3(1.1, 1.1, 0), rot_z(deg2rad(45.0)) * rot_x(deg2rad(45.0)), Vec3(0.5, 0.05, 0.05)};
  EXPECT_EQ(boxes_intersect(a, c, 0.0), boxes_intersect(c, a, 0.0));
}

TEST(SimWideSite, SideBySidePanelsHangOnAFrame) {
  AntennaLayout L;
  L.mast_radius_m = 0.05;
  for (int k = 0; k < 2; ++k) {
    SimAntenna a;
    a.name = "antenna-" + std::to_string(k + 1);
    a.azimuth_magnetic = deg2rad(30.0 + 4.0 * k);
    a.downtilt = deg2rad(6.0);
    a.R_world_antenna = rot_z(-a.azimuth_magnetic) * rot_x(-a.downtilt);
    L.antennas.push_back(a);
  }
  FrameSpec f;
  f.facing = deg2rad(32.0);
  f.offsets_m = {-0.25, 0.25};
  f.z_m = 2.5;
  ASSERT_TRUE(mount_side_by_side(L, f, {0.1, 0.1}));
  EXPECT_EQ(L.arrangement, Arrangement::kSideBySide);
  EXPECT_EQ(L.frame.size(), 6u);  // two bars, two stand-offs, two pipes
  EXPECT_FALSE(layout_collides(L, 0.01, 0.3));
  for (const SimAntenna& a : L.antennas) {
    // Each arm ends on its pipe's axis, 10 cm + pipe radius from the nearer bracket.
    const auto arms = antenna_arms(a);
    EXPECT_NEAR((arms[0].axis_point.head<2>() - a.mount_xy).norm(), 0.0, 1e-12);
    EXPECT_NEAR(std::min(arms[0].length_m, arms[1].length_m), a.mount_radius_m + 0.1, 0.02);
  }
  // Too close: the panels' boxes meet.
  f.offsets_m = {-0.1, 0.1};
  ASSERT_TRUE(mount_side_by_side(L, f, {0.1, 0.1}));
  EXPECT_TRUE(layout_collides(L, 0.01, 0.3));
}

TEST(SimWideSite, SkyDomeIsAGradientAndTheDefaultSkyIsUniform) {
  camera::CameraIntrinsics K;
  K.width = 64, K.height = 48, K.fx = K.fy = 40, K.cx = 31.5, K.cy = 23.5;
  const PhotoRenderer renderer(K, 1);
  CameraPose up;  // looking up at 45°, image down towards the horizon
  up.R_world_camera = rot_x(deg2rad(45.0)) * (Mat3() << 1, 0, 0, 0, 0, 1, 0, -1, 0).finished();
  const cv::Mat uniform_sky = renderer.render(Scene{}, up, Lighting{});
  double lo = 0, hi = 0;
  cv::minMaxLoc(uniform_sky, &lo, &hi);
  EXPECT_EQ(lo, static_cast<double>(0.9f));
  EXPECT_EQ(hi, static_cast<double>(0.9f));
  Lighting L;
  L.dome = SkyDome{0.6, 1.0, nullptr};
  EXPECT_NEAR(sky_radiance(L, Vec3(0, 0, 1)), 0.6, 1e-12);
  EXPECT_NEAR(sky_radiance(L, Vec3(1, 0, 0)), 1.0, 1e-12);
  EXPECT_NEAR(sky_radiance(L, Vec3(1, 0, -1)), 1.0, 1e-12);
  const cv::Mat dome = renderer.render(Scene{}, up, L);
  EXPECT_LT(dome.at<float>(0, 32), dome.at<float>(47, 32));  // top of the image nearer the zenith
}

TEST(SimWideSite, GaitBobHasTheAnalyticAccelerationAndStillHolds) {
  Trajectory tr(Mat3::Identity(), Vec3::Zero());
  tr.hold(1.0);
  tr.walk_to(rot_z(0.3), Vec3(1.0, 0.5, 0.0), 1.6, GaitBob{0.02, 1.9});
  tr.hold(1.0);
  const double h = 1e-4;
  double bob_max = 0;
  for (double t = 1.05; t < 2.6; t += 0.05) {
    const Vec3 fd = (tr.position_world(t + h) - 2 * tr.position_world(t) + tr.position_world(t - h)) / (h * h);
    EXPECT_LT((fd - tr.acceleration_world(t)).norm(), 1e-3) << t;
    bob_max = std::max(bob_max, std::abs(tr.position_world(t).z()));
  }
  EXPECT_GT(bob_max, 0.01);
  EXPECT_LE(bob_max, 0.02);
  EXPECT_EQ(tr.position_world(0.99).z(), 0.0);
  EXPECT_NEAR(tr.position_world(2.61).z(), 0.0, 1e-15);
  EXPECT_LT(tr.acceleration_world(2.601).norm(), 1e-6);  // the hold after the walk is still
}

// A low-resolution wide capture: two panels side by side on a monopole, trees behind, a low sun.
class SimWideCapture : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir();
    CaptureScenario sc;
    sc.scenario = Scenario::kAntenna;
    sc.seed = 11;
    sc.device.width = 2400, sc.device.height = 1800;  // 4.3 MP: photos of 2–4.3 MP
    sc.device.supersampling = 1;
    sc.photos = 5;
    sc.setting = AntennaSetting::kGround;
    sc.antennas = 2;
    sc.wide.arrangement = Arrangement::kSideBySide;
    sc.wide.background = BackgroundKind::kTrees;
    sc.wide.light = LightMode::kLowSun;
    sim_ = new SimulatedCapture(write_simulated_capture(sc, dir_->path() / "wide", false));
  }
  static void TearDownTestSuite() {
    delete sim_;
    delete dir_;
  }
  static fs::path folder() { return dir_->path() / "wide"; }
  static test::TempDir* dir_;
  static SimulatedCapture* sim_;
};
test::TempDir* SimWideCapture::dir_ = nullptr;
SimulatedCapture* SimWideCapture::sim_ = nullptr;

TEST_F(SimWideCapture, PhotosAreOfTheResizedCamera) {
  const YAML::Node device = YAML::LoadFile((folder() / "truth/device.yaml").string());
  const auto K = test::intrinsics_of(device);
  const double s = device["photo_scale"].as<double>();
  EXPECT_GE(K.width * static_cast<double>(K.height), 2e6 - 1e4);
  EXPECT_EQ(K.width, std::lround(2400 * s));
  EXPECT_EQ(K.height, std::lround(1800 * s));
  const auto native = device["native_camera"];
  EXPECT_EQ(native["width_px"].as<int>(), 2400);
  EXPECT_NEAR(K.fx, native["fx_px"].as<double>() * K.width / 2400.0, 1e-9);
  EXPECT_NEAR(K.fy, native["fy_px"].as<double>() * K.height / 1800.0, 1e-9);
  EXPECT_NEAR(K.cx, (native["cx_px"].as<double>() + 0.5) * K.width / 2400.0 - 0.5, 1e-9);
  EXPECT_NEAR(K.cy, (native["cy_px"].as<double>() + 0.5) * K.height / 1800.0 - 0.5, 1e-9);
  for (std::size_t i = 0; i < 5; ++i) EXPECT_NEAR(K.distortion[i], native["distortion"][i].as<double>(), 1e-12);
  EXPECT_LE(std::abs(device["camera_imu"]["time_offset_s"].as<double>()), 0.15);
  const cv::Mat img = cv::imread((folder() / "images/img_0000.jpg").string(), cv::IMREAD_GRAYSCALE);
  EXPECT_EQ(img.cols, K.width);
  EXPECT_EQ(img.rows, K.height);
}

// The recording's accelerometer and gyroscope offsets have moved from the phone's own (which its
// calibration captures show) by about their 1σ of 1.5 mg and 0.05 °/s per axis, and the truth
// says so.
TEST_F(SimWideCapture, TheImuOffsetsAreTheRecordingsNotTheCalibrations) {
  CaptureScenario sc;
  const SimulatedDevice calibrated = make_device(sc.device, 11);
  const Vec3 acc = sim_->device.phone.accelerometer.bias - calibrated.phone.accelerometer.bias;
  const Vec3 gyro = sim_->device.phone.gyroscope.bias - calibrated.phone.gyroscope.bias;
  EXPECT_GT(acc.cwiseAbs().minCoeff(), 1e-6);
  EXPECT_LT(acc.cwiseAbs().maxCoeff(), 5 * 1.5e-3 * 9.80665);
  EXPECT_GT(gyro.cwiseAbs().minCoeff(), 1e-9);
  EXPECT_LT(gyro.cwiseAbs().maxCoeff(), 5 * deg2rad(0.05));
  const YAML::Node device = YAML::LoadFile((folder() / "truth/device.yaml").string());
  for (int i = 0; i < 3; ++i)
    EXPECT_NEAR(device["accelerometer"]["bias"][i].as<double>(), sim_->device.phone.accelerometer.bias(i), 1e-6);
}

TEST_F(SimWideCapture, TruthRoiHoldsTheRenderedPanel) {
  const YAML::Node scene = YAML::LoadFile((folder() / "truth/scene.yaml").string());
  EXPECT_EQ(scene["distribution"].as<std::string>(), "wide");
  EXPECT_EQ(scene["arrangement"].as<std::string>(), "side-by-side");
  EXPECT_EQ(scene["background"]["kind"].as<std::string>(), "trees");
  EXPECT_EQ(scene["light"]["mode"].as<std::string>(), "low-sun");
  EXPECT_GE(scene["frame"].size(), 5u);
  const AntennaTruth& at = *sim_->antenna;
  ASSERT_EQ(scene["antennas"].size(), 2u);
  const camera::CameraIntrinsics& K = sim_->device.intrinsics;
  for (std::size_t k = 0; k < 2; ++k) {
    const auto a = scene["antennas"][k];
    const SimAntenna& ant = at.layout.antennas[k];
    EXPECT_EQ(a["model"].as<std::string>(), ant.model_name);
    EXPECT_NO_THROW(model::builtin_panel(a["model"].as<std::string>()));
    const auto roi = a["roi"];
    const cv::Rect box(roi["x"].as<int>(), roi["y"].as<int>(), roi["width"].as<int>(), roi["height"].as<int>());
    const int shot = at.roi_shot[k];
    EXPECT_EQ(roi["image"].as<std::string>(), sim_->shots[static_cast<std::size_t>(shot)].image);
    const CameraPose pose{sim_->shots[static_cast<std::size_t>(shot)].R_world_camera,
                          sim_->shots[static_cast<std::size_t>(shot)].p_world_camera};
    for (const Vec3& v : rendered_panel_mesh(ant).vertices) {
      const auto uv = project_world(K, pose, ant.p_world_antenna + ant.R_world_antenna * v);
      ASSERT_TRUE(uv.has_value());
      EXPECT_TRUE(box.contains(cv::Point(static_cast<int>(uv->x()), static_cast<int>(uv->y()))));
    }
    // At least 70 % of it shows in its ROI photo, half of it in three photos.
    const auto& f = at.visible_fraction[k];
    EXPECT_GE(f[static_cast<std::size_t>(shot)], 0.7);
    EXPECT_GE(std::count_if(f.begin(), f.end(), [](double v) { return v >= 0.5; }), 3);
    EXPECT_NEAR(a["width_px"].as<double>(), apparent_width_px(K, pose, ant), 0.06);
    EXPECT_GT(a["width_px"].as<double>(), 0.0);
    EXPECT_TRUE(a["finish"]["radome_albedo"].IsDefined());
    EXPECT_TRUE(a["panel"]["bracket_end_fraction"].IsDefined());
  }
}

}  // namespace
}  // namespace antpose::sim
