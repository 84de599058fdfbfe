// Device profile YAML: round trip of every section with unknown keys, and every bad value's
// message (file, line, value, expected).
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/io/text_file.hpp"
#include "antpose/store/device_profile.hpp"
#include "support/test_support.hpp"

namespace antpose::store {
namespace {

using ::testing::HasSubstr;
namespace fs = std::filesystem;

const std::string kFull = R"(format: antpose-device
version: 1
device: {model: Pixel 7, id: px7, colour: blue}
site_note: {who: me}
imu:
  accelerometer: {bias_m_s2: [0.1, -0.02, 0.03], scale: [1.001, 0.999, 1], residual_rms_m_s2: 0.004}
  gyroscope: {bias_rad_s: [0.001, 0, -0.002]}
  thermometer: {offset_K: 0.3}
camera:
  width_px: 4000
  height_px: 3000
  fx_px: 3012.5
  fy_px: 3010.25
  cx_px: 1999.5
  cy_px: 1501.75
  distortion: [0.11, -0.21, 0.001, -0.002, 0.05]
  rms_px: 0.41
  lens: wide
camera_imu:
  R_device_camera: [[0.9998, -0.0175, 0.0087], [-0.0174, -0.9998, -0.0052], [0.0088, 0.0051, -0.99995]]
  rotation_sigma_deg: [0.1, 0.2, 0.3]
  time_offset_s: 0.012
  time_offset_sigma_s: 0.002
  method: reference-free
  board: A3
)";

// An exact rotation close to the nominal one (the literal above is only approximately orthonormal).
Mat3 exact_rotation() {
  return Eigen::AngleAxisd(0.01, Vec3(0.3, -0.5, 0.8).normalized()).toRotationMatrix() * camera::nominal_R_device_camera();
}

std::string with_exact_rotation(std::string text) {
  const Mat3 R = exact_rotation();
  const auto pos = text.find("  R_device_camera:");
  const auto end = text.find('\n', pos);
  text.replace(pos, end - pos,
               fmt::format("  R_device_camera: [[{:.17g}, {:.17g}, {:.17g}], [{:.17g}, {:.17g}, {:.17g}], [{:.17g}, "
                           "{:.17g}, {:.17g}]]",
                           R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)));
  return text;
}

TEST(DeviceProfile, ParsesEverySection) {
  const DeviceProfile p = parse_device_profile(with_exact_rotation(kFull), "p.yaml");
  EXPECT_EQ(p.id, "px7");
  EXPECT_EQ(p.model, "Pixel 7");
  EXPECT_TRUE(p.has_imu);
  EXPECT_NEAR(p.imu.acc_bias.x(), 0.1, 1e-15);
  ASSERT_TRUE(p.camera);
  EXPECT_EQ(p.camera->intrinsics.width, 4000);
  EXPECT_DOUBLE_EQ(p.camera->intrinsics.fy, 3010.25);
  EXPECT_DOUBLE_EQ(p.camera->intrinsics.distortion[4], 0.05);
  EXPECT_DOUBLE_EQ(*p.camera->rms_px, 0.41);
  ASSERT_TRUE(p.camera_imu);
  EXPECT_TRUE(p.camera_imu->R_device_camera.isApprox(exact_rotation(), 1e-15));
  EXPECT_NEAR(p.camera_imu->rotation_sigma_rad->z(), 0.3 * M_PI / 180, 1e-15);
  EXPECT_DOUBLE_EQ(p.camera_imu->time_offset_s, 0.012);
  EXPECT_DOUBLE_EQ(*p.camera_imu->time_offset_sigma_s, 0.002);
  EXPECT_EQ(p.camera_imu->method, "reference-free");
}

TEST(DeviceProfile, RoundTripKeepsValuesAndUnknownKeys) {
  const DeviceProfile p = parse_device_profile(with_exact_rotation(kFull), "p.yaml");
  const std::string text = format_device_profile(p);
  for (const char* key : {"colour: blue", "site_note", "thermometer", "offset_K: 0.3", "lens: wide", "board: A3"})
    EXPECT_THAT(text, HasSubstr(key)) << text;
  const DeviceProfile q = parse_device_profile(text, "q.yaml");
  EXPECT_EQ(q.id, p.id);
  EXPECT_EQ(q.model, p.model);
  EXPECT_EQ(q.imu.acc_bias, p.imu.acc_bias);
  EXPECT_EQ(q.imu.acc_scale, p.imu.acc_scale);
  EXPECT_EQ(q.imu.gyro_bias, p.imu.gyro_bias);
  EXPECT_EQ(q.camera->intrinsics.distortion, p.camera->intrinsics.distortion);
  EXPECT_EQ(q.camera->intrinsics.cx, p.camera->intrinsics.cx);
  EXPECT_EQ(q.camera_imu->R_device_camera, p.camera_imu->R_device_camera);  // round-trip digits: bit-exact
  EXPECT_NEAR((*q.camera_imu->rotation_sigma_rad - *p.camera_imu->rotation_sigma_rad).norm(), 0, 1e-17);
  EXPECT_EQ(q.camera_imu->time_offset_s, p.camera_imu->time_offset_s);
  EXPECT_EQ(format_device_profile(q), text);  // a fixed point
}

TEST(DeviceProfile, SectionsAreOptionalAndRemovable) {
  const DeviceProfile cam_only = parse_device_profile(
      "format: antpose-device\nversion: 1\ncamera: {width_px: 640, height_px: 480, fx_px: 500, fy_px: 500, cx_px: 320, "
      "cy_px: 240}\n",
      "c.yaml");
  EXPECT_FALSE(cam_only.has_imu);
  EXPECT_FALSE(cam_only.camera_imu);
  ASSERT_TRUE(cam_only.camera);
  EXPECT_FALSE(cam_only.camera->intrinsics.has_distortion());
  EXPECT_THAT(format_device_profile(cam_only), ::testing::Not(HasSubstr("imu")));
  const DeviceProfile flow = parse_device_profile(
      "{format: antpose-device, version: 1, device: {id: f1}, camera_imu: {time_offset_s: 0.02}}", "flow.yaml");
  EXPECT_EQ(flow.id, "f1");
  EXPECT_FALSE(flow.has_imu);
  EXPECT_DOUBLE_EQ(flow.camera_imu->time_offset_s, 0.02);

  DeviceProfile p = parse_device_profile(with_exact_rotation(kFull), "p.yaml");
  p.camera.reset();
  p.camera_imu.reset();
  const std::string text = format_device_profile(p);
  EXPECT_THAT(text, ::testing::Not(HasSubstr("camera")));
  EXPECT_THAT(text, HasSubstr("thermometer"));
}

TEST(DeviceProfile, WriteAndReadFile) {
  test::TempDir dir;
  DeviceProfile p;
  p.id = "a1";
  p.model = "M";
  p.camera_imu = CameraImuCalibration{};
  p.camera_imu->time_offset_s = -0.25;
  write_device_profile(p, dir / "a.yaml");
  const DeviceProfile q = read_device_profile(dir / "a.yaml");
  EXPECT_EQ(q.id, "a1");
  EXPECT_EQ(q.camera_imu->time_offset_s, -0.25);
  EXPECT_EQ(q.camera_imu->R_device_camera, camera::nominal_R_device_camera());
}

struct BadCase {
  std::string from, to;  // replace in kFull (with the exact rotation)
  int line;
  std::vector<std::string> needles;
};

TEST(DeviceProfile, EveryBadValueNamesFileLineValueAndExpectation) {
  const std::vector<BadCase> cases = {
      {"  width_px: 4000", "  width_px: -4", 10, {"camera.width_px = -4", "positive image size"}},
      {"  height_px: 3000", "  height_px: big", 11, {"camera.height_px", "'big'"}},
      {"  fx_px: 3012.5", "  fx_px: nan", 12, {"camera.fx_px"}},
      {"  cx_px: 1999.5", "  cx_px: 5000", 10, {"principal point", "inside the image"}},
      {"  fx_px: 3012.5", "  fx_px: 0", 10, {"camera intrinsics are", "focal length"}},
      {"  distortion: [0.11, -0.21, 0.001, -0.002, 0.05]", "  distortion: [0.11, -0.21]", 16,
       {"camera.distortion is a list of 2", "5 numbers"}},
      {"  rms_px: 0.41", "  rms_px: -1", 17, {"camera.rms_px = -1", "≥ 0"}},
      {"  rotation_sigma_deg: [0.1, 0.2, 0.3]", "  rotation_sigma_deg: [0.1, -0.2, 0.3]", 21,
       {"rotation_sigma_deg = [0.1, -0.2, 0.3]", "≥ 0"}},
      {"  time_offset_s: 0.012", "  time_offset_s: 1.5", 22, {"time_offset_s = 1.5 s", "|offset| < 1 s", "clock"}},
      {"  time_offset_s: 0.012", "  time_offset_s: -1", 22, {"time_offset_s = -1 s"}},
      {"  time_offset_sigma_s: 0.002", "  time_offset_sigma_s: -0.1", 23, {"time_offset_sigma_s = -0.1"}},
      {"  method: reference-free", "  method: [a, b]", 24, {"camera_imu.method"}},
      {"camera:\n  width_px", "camera: 7\nx:\n  width_px", 9, {"camera"}},
  };
  for (const auto& c : cases) {
    std::string text = with_exact_rotation(kFull);
    const auto pos = text.find(c.from);
    ASSERT_NE(pos, std::string::npos) << c.from;
    text.replace(pos, c.from.size(), c.to);
    try {
      parse_device_profile(text, "bad.yaml");
      ADD_FAILURE() << "accepted: " << c.to;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), fs::path("bad.yaml")) << c.to;
      EXPECT_EQ(e.line(), static_cast<std::size_t>(c.line)) << c.to << ": " << e.what();
      for (const auto& n : c.needles) EXPECT_THAT(e.what(), HasSubstr(n)) << c.to;
    }
  }
}

TEST(DeviceProfile, RotationChecksSayWhatWasFound) {
  auto bad = [](const std::string& matrix) {
    std::string text = kFull;
    const auto pos = text.find("  R_device_camera:");
    text.replace(pos, text.find('\n', pos) - pos, "  R_device_camera: " + matrix);
    try {
      parse_device_profile(text, "r.yaml");
    } catch (const InputError& e) {
      EXPECT_EQ(e.line(), 20u);
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string scaled = bad("[[1.01, 0, 0], [0, -1, 0], [0, 0, -1]]");
  EXPECT_THAT(scaled, HasSubstr("not a rotation"));
  EXPECT_THAT(scaled, HasSubstr("max |RᵀR − I| = 0.0201"));
  const std::string reflection = bad("[[1, 0, 0], [0, 1, 0], [0, 0, -1]]");
  EXPECT_THAT(reflection, HasSubstr("det = -1"));
  EXPECT_THAT(reflection, HasSubstr("reflection"));
  EXPECT_THAT(bad("[[1, 0, 0], [0, -1, 0]]"), HasSubstr("R_device_camera"));
  // The approximate literal of kFull (4-5 digits) is rejected too: 1e-6 is the tolerance.
  EXPECT_THROW(parse_device_profile(kFull, "approx.yaml"), InputError);
}

TEST(DeviceProfile, ImuErrorsKeepTheirLines) {
  std::string text = with_exact_rotation(kFull);
  text.replace(text.find("scale: [1.001, 0.999, 1]"), 24, "scale: [3.000, 0.999, 1]");
  try {
    parse_device_profile(text, "i.yaml");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.line(), 6u);
    EXPECT_THAT(e.what(), HasSubstr("imu.accelerometer.scale"));
  }
  // A profile without imu still checks format and version.
  EXPECT_THROW(parse_device_profile("format: other\nversion: 1\n", "f.yaml"), InputError);
  EXPECT_THROW(read_device_profile("/nonexistent/x.yaml"), InputError);
}

}  // namespace
}  // namespace antpose::store
