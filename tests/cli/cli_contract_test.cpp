// The command line's contract with scripts: exit statuses, `--json -`, outputs that are not
// regular files, inputs that are not regular files or lead out of the capture.
#include <sys/stat.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::Not;

const std::string kWmm = "wmm --lat 45 --lon 7 --date 2026-06-01";

// A copy of the bundled contact capture to damage.
fs::path contact_copy(const test::TempDir& dir) {
  const fs::path to = dir / "contact";
  fs::copy(test::source_path("examples/contact-sample"), to, fs::copy_options::recursive);
  return to;
}

TEST(CliContract, MisuseIsBadInputAndAMistypedVerbIsNamed) {
  auto r = test::run_cli("mesure capture");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("unknown verb 'mesure' (did you mean 'measure'?); the verbs are convert,"));
  r = test::run_cli("measure");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("capture is required"));
  r = test::run_cli(kWmm + " --no-such-option");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--no-such-option"));
  r = test::run_cli("--help");
  EXPECT_EQ(r.status, 0);
  EXPECT_THAT(r.out, HasSubstr("Exit status: 0 every requested result is usable; 2 bad input"));
}

TEST(CliContract, ANumberOptionIsCheckedBeforeAnyWork) {
  // A non-finite offset, or one outside the search bracket, is refused before the capture is read.
  for (const char* offset : {"nan", "5", "inf"}) {
    const auto r =
        test::run_cli(fmt::format("calibrate joint no-capture --device p.yaml --time-offset {} "
                                  "--fixed-time-offset",
                                  offset));
    EXPECT_EQ(r.status, 2) << offset;
    EXPECT_THAT(r.err, HasSubstr(fmt::format("--time-offset: {} must be within [-0.2, 0.2] s", offset)));
  }
}

TEST(CliContract, AnUnknownOrientationMethodIsRefusedBeforeAnyWorkUnderItsOwnName) {
  const auto r = test::run_cli("measure no-capture --device p.yaml --roi a.jpg:1,2,30,40 --method bogus");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--method: 'bogus' is not an orientation method, expected ecompass"));
}

TEST(CliContract, EveryVerbTakesItsOrientationMethodAsMethod) {
  // measure, calibrate joint, orientation and bench orientation all take --method; each checks
  // the names while parsing, before reading the capture.
  for (const char* line :
       {"measure no-capture --device p.yaml --roi a.jpg:1,2,30,40 --method kalman",
        "calibrate joint no-capture --method kalman", "orientation no-capture -o o.csv --method kalman",
        "bench orientation no-capture --method madgwick,kalman"}) {
    const auto r = test::run_cli(line);
    EXPECT_EQ(r.status, 2) << line;
    EXPECT_THAT(r.err, HasSubstr("--method: 'kalman' is not an orientation method")) << line;
  }
  // One method where the verb uses one.
  auto r = test::run_cli("measure no-capture --device p.yaml --roi a.jpg:1,2,30,40 --method madgwick,mahony");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("'madgwick,mahony': one orientation method only"));
  // Command lines written for the older option names fail with the new name, not with a different meaning.
  r = test::run_cli("measure no-capture --device p.yaml --roi a.jpg:1,2,30,40 --orientation madgwick");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--orientation: this option is now called --method (given 'madgwick')"));
  r = test::run_cli("bench orientation no-capture --methods madgwick");
  EXPECT_THAT(r.err, HasSubstr("--methods: this option is now called --method"));
  r = test::run_cli("calibrate joint no-capture --method reference-free");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("'reference-free' is not an orientation method: the calibration solver is --solver"));
}

TEST(CliContract, JsonToStandardOutputIsAloneThere) {
  const auto r = test::run_cli(kWmm + " --json -");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);  // nothing but the JSON
  EXPECT_NEAR(j["declination_deg"].get<double>(), 3.2, 0.3);
  EXPECT_THAT(r.err, HasSubstr("declination D:"));  // the human-readable text moved to stderr
  EXPECT_FALSE(fs::exists("-"));
}

TEST(CliContract, OutputsThatAreNotRegularFilesAreWrittenOrRefusedNeverReplaced) {
  test::TempDir dir;
  // /dev/stdout is the test's capture file here: written through the open descriptor, after the text.
  auto r = test::run_cli(kWmm + " --json /dev/stdout");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_LT(r.out.find("declination D:"), r.out.find("\"declination_deg\""));  // nothing overwritten
  EXPECT_TRUE(fs::is_symlink("/dev/stdout"));
  r = test::run_cli(kWmm + " --json /dev/full");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("error: /dev/full: cannot write (No space left on device)"));
  EXPECT_TRUE(fs::is_character_file("/dev/full"));
  fs::create_directories(dir / "out");
  r = test::run_cli(fmt::format("{} --json '{}'", kWmm, (dir / "out").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("out: is a folder; give a file name for the output"));
  fs::create_symlink("real.json", dir / "link.json");
  r = test::run_cli(fmt::format("{} --json '{}'", kWmm, (dir / "link.json").string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::is_symlink(dir / "link.json"));
  EXPECT_TRUE(nlohmann::json::parse(io::read_text(dir / "real.json")).contains("declination_deg"));
}

TEST(CliContract, ACaptureFileThatIsAFifoIsRefusedNotWaitedFor) {
  test::TempDir dir;
  const fs::path cap = contact_copy(dir);
  fs::remove(cap / "capture.yaml");
  ASSERT_EQ(::mkfifo((cap / "capture.yaml").c_str(), 0600), 0);
  for (const char* verb : {"inspect", "contact"}) {
    const auto r = test::run_cli(fmt::format("{} '{}'", verb, cap.string()));
    EXPECT_EQ(r.status, 2) << verb;
    EXPECT_THAT(r.err, HasSubstr("capture.yaml: is a FIFO (named pipe), expected a regular file")) << verb;
  }
}

TEST(CliContract, PathsInACaptureNeverLeadOutOfItNorEchoWhatTheyName) {
  test::TempDir dir;
  const fs::path cap = contact_copy(dir);
  test::write_file(dir / "secret.csv", "SECRET-LINE\n");
  const std::string yaml = io::read_text(cap / "capture.yaml");
  const std::string key = "orientation: truth/orientation.csv";
  ASSERT_NE(yaml.find(key), std::string::npos);
  const auto with_truth = [&](const std::string& value) {
    std::string text = yaml;
    text.replace(text.find(key), key.size(), "orientation: " + value);
    test::write_file(cap / "capture.yaml", text);
    return test::run_cli(fmt::format("inspect '{}'", cap.string()));
  };
  auto r = with_truth("/dev/zero");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("capture.yaml:17: truth.orientation '/dev/zero' is an absolute path"));
  r = with_truth("../secret.csv");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("truth.orientation '../secret.csv' leads out of the capture folder"));
  fs::create_symlink(dir / "secret.csv", cap / "truth" / "linked.csv");
  r = with_truth("truth/linked.csv");
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("leads out of the capture folder through a symbolic link"));
  EXPECT_THAT(r.err + r.out, Not(HasSubstr("SECRET")));
  // A stream linked to a file outside the capture, too.
  test::write_file(cap / "capture.yaml", yaml);
  fs::remove(cap / "sensors" / "magnetometer.csv");
  fs::create_symlink(dir / "secret.csv", cap / "sensors" / "magnetometer.csv");
  r = test::run_cli(fmt::format("contact '{}'", cap.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err,
              HasSubstr("stream 'sensors/magnetometer.csv' leads out of the capture folder through a symbolic link"));
  EXPECT_THAT(r.err + r.out, Not(HasSubstr("SECRET")));
}

TEST(CliContract, AnAttitudeIsNotReadFromAxesOfAnUnknownFrame) {
  test::TempDir dir;
  const fs::path cap = contact_copy(dir);
  std::string yaml = io::read_text(cap / "capture.yaml");
  yaml.replace(yaml.find("sensor_frame: android"), 21, "sensor_frame: other");
  test::write_file(cap / "capture.yaml", yaml);
  const auto r = test::run_cli(fmt::format("contact '{}'", cap.string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("capture.yaml: sensor_frame 'other': the contact measurement needs the streams in "
                               "Android's device frame"));
}

TEST(CliContract, ContactTakesTheDevicesImuCalibration) {
  test::TempDir dir;
  const fs::path device = dir / "phone.yaml";
  ASSERT_EQ(test::run_cli(fmt::format("calibrate imu '{}' --sensors mag -o '{}'",
                                      test::source_path("examples/imu-calibration-sample").string(), device.string()))
                .status,
            0);
  const fs::path cap = test::source_path("examples/contact-sample");
  const auto by_file =
      test::run_cli(fmt::format("contact '{}' --imu-calibration '{}' --json -", cap.string(), device.string()));
  const auto by_device =
      test::run_cli(fmt::format("contact '{}' --device '{}' --json -", cap.string(), device.string()));
  ASSERT_EQ(by_file.status, 0) << by_file.err;
  ASSERT_EQ(by_device.status, 0) << by_device.err;
  const auto a = nlohmann::json::parse(by_file.out), b = nlohmann::json::parse(by_device.out);
  EXPECT_EQ(a["azimuth_magnetic_deg"], b["azimuth_magnetic_deg"]);
  EXPECT_EQ(a["downtilt_deg"], b["downtilt_deg"]);
  EXPECT_FALSE(b["provenance"]["device"].is_null());
  const auto both = test::run_cli(
      fmt::format("contact '{}' --device '{}' --imu-calibration '{}'", cap.string(), device.string(), device.string()));
  EXPECT_EQ(both.status, 2);
  EXPECT_THAT(both.err, HasSubstr("--device: give --device or --imu-calibration, not both"));
}

TEST(CliContract, AResultOverTheSigmaLimitIsWrittenAndExitsFour) {
  test::TempDir dir;
  const fs::path cap = contact_copy(dir);
  const fs::path json = dir / "contact.json";
  auto r = test::run_cli(fmt::format("contact '{}' --json '{}'", cap.string(), json.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  r = test::run_cli(fmt::format("contact '{}' --max-sigma-deg 0.01 --json '{}'", cap.string(), json.string()));
  EXPECT_EQ(r.status, 4) << r.err;
  EXPECT_THAT(r.err, HasSubstr("warning: the result is not usable: azimuth sigma"));
  EXPECT_THAT(r.err, HasSubstr("over --max-sigma-deg 0.01"));
  const auto j = nlohmann::json::parse(io::read_text(json));
  EXPECT_TRUE(j.contains("downtilt_deg"));
  EXPECT_EQ(j["provenance"]["command"], "contact");
  EXPECT_EQ(j["provenance"]["inputs"][0]["role"], "capture");
  EXPECT_EQ(j["provenance"]["options"]["--max-sigma-deg"], "0.01");
  r = test::run_cli(fmt::format("contact '{}' --max-sigma-deg -1", cap.string()));
  EXPECT_EQ(r.status, 2);
}

}  // namespace
}  // namespace antpose
