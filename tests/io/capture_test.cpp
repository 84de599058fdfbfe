// Native capture folder: lossless round trip and every bad-input message.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <random>

#include <unistd.h>

#include <fmt/format.h>

#include "antpose/io/capture.hpp"
#include "antpose/io/csv.hpp"
#include "antpose/io/import.hpp"
#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose {
namespace {

namespace fs = std::filesystem;
using test::TempDir;
using test::write_file;
using ::testing::HasSubstr;

constexpr const char* kYaml = "format: antpose-capture\nversion: 1\nkind: imu-log\n";

// A minimal valid capture: 1 s of 100 Hz accelerometer, gyroscope and magnetometer data.
void write_minimal(const fs::path& dir, const std::string& yaml = kYaml) {
  write_file(dir / "capture.yaml", yaml);
  std::string acc = "t,x,y,z\n", gyr = "t,x,y,z\n", mag = "t,x,y,z\n";
  for (int i = 0; i < 100; ++i) {
    const double t = i * 0.01;
    acc += fmt::format("{},0.1,0.2,9.8\n", t);
    gyr += fmt::format("{},0.01,0,0\n", t);
    mag += fmt::format("{},20,-30,25\n", t);
  }
  write_file(dir / "sensors" / "accelerometer.csv", acc);
  write_file(dir / "sensors" / "gyroscope.csv", gyr);
  write_file(dir / "sensors" / "magnetometer.csv", mag);
}

std::string error_of(const fs::path& dir, const CaptureReadOptions& options = {}) {
  Diagnostics d;
  try {
    read_capture(dir, d, options);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

bool bit_identical(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expect_streams_identical(const Stream& a, const Stream& b) {
  ASSERT_EQ(a.size(), b.size()) << a.name;
  ASSERT_EQ(a.columns, b.columns) << a.name;
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_TRUE(bit_identical(a.t[i], b.t[i])) << a.name << " t row " << i;
    for (Eigen::Index k = 0; k < a.values.cols(); ++k)
      ASSERT_TRUE(bit_identical(a.values(static_cast<Eigen::Index>(i), k), b.values(static_cast<Eigen::Index>(i), k)))
          << a.name << " row " << i << " col " << k;
  }
}

TEST(CaptureRoundTrip, ReadWriteReadIsLossless) {
  TempDir dir;
  const fs::path in = dir / "in";
  write_file(in / "capture.yaml",
             "format: antpose-capture\nversion: 1\nkind: contact\ntime_origin: 2014-01-04T11:34:44.114Z\n"
             "device:\n  model: Samsung C101\n  id: c101-lab\n  colour: blue\nsensor_frame: android\n"
             "site:\n  lat_deg: 30.26\n  lon_deg: 120.12\n  alt_m: 20\n  date: 2014-01-04\n"
             "truth:\n  orientation: truth/orientation.csv.gz\n  world: enu-magnetic\n  note: simulated\n"
             "source:\n  name: unit test\n  licence: none\nmy_unknown_key:\n  nested: [1, 2, 3]\n");
  // Awkward doubles: 17 significant digits, subnormal, huge, negative zero.
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(-20.0, 20.0);
  std::string acc = "t,x,y,z,temperature\n";
  for (int i = 0; i < 200; ++i)
    acc += fmt::format("{},{},{},{},{}\n", io::format_number(0.1 + i * 0.01 + u(rng) * 1e-6), io::format_number(0.1 * u(rng)),
                       io::format_number(0.1 * u(rng) + 9.8), io::format_number(i == 3 ? 4.9e-324 : 0.1 * u(rng)),
                       io::format_number(i == 5 ? -0.0 : 1e300 * u(rng)));
  write_file(in / "sensors" / "accelerometer.csv", acc);
  std::string gyr = "t,x,y,z\n";
  for (int i = 0; i < 150; ++i) gyr += fmt::format("{},{},{},{}\n", io::format_number(0.1 + i * 0.013), io::format_number(u(rng)), 0.5, -0.25);
  io::write_text_atomic(in / "sensors" / "gyroscope.csv.gz", gyr);
  write_file(in / "shots.csv", "index,t,image,exposure_s,placement,comment\n0,0.5,images/a.jpg,0.01,hor_0_90,\"first, with comma\"\n"
                               "1,1.5,images/b.png,,down_20,\n");
  write_file(in / "images" / "a.jpg", "JPEG bytes");
  write_file(in / "images" / "b.png", "PNG bytes");
  io::write_text_atomic(in / "truth" / "orientation.csv.gz", "t,qw,qx,qy,qz,valid\n0.1,1,0,0,0,1\n0.2,nan,nan,nan,nan,0\n");
  write_file(in / "board.yaml", "type: chessboard\ncols: 9\nrows: 6\nsquare_m: 0.025\n");
  write_file(in / "truth" / "scene.yaml", "antenna: {}\n");

  Diagnostics d1;
  const Capture a = read_capture(in, d1);
  const fs::path out = dir / "out";
  write_capture(a, out);
  Diagnostics d2;
  const Capture b = read_capture(out, d2);

  EXPECT_EQ(b.kind, "contact");
  EXPECT_EQ(b.time_origin, a.time_origin);
  EXPECT_EQ(b.device_model, "Samsung C101");
  EXPECT_EQ(b.device_id, "c101-lab");
  ASSERT_TRUE(b.site.has_value());
  EXPECT_TRUE(bit_identical(b.site->lat_deg, 30.26));
  EXPECT_TRUE(bit_identical(b.site->lon_deg, 120.12));
  EXPECT_EQ(b.site->date, "2014-01-04");
  ASSERT_EQ(b.streams.size(), 2u);
  expect_streams_identical(a.require("accelerometer"), b.require("accelerometer"));
  expect_streams_identical(a.require("gyroscope"), b.require("gyroscope"));
  EXPECT_TRUE(b.require("gyroscope").gzip);
  EXPECT_TRUE(fs::exists(out / "sensors" / "gyroscope.csv.gz"));
  // Unknown keys survive, nested.
  EXPECT_EQ(b.metadata["my_unknown_key"]["nested"][2].as<int>(), 3);
  EXPECT_EQ(b.metadata["source"]["licence"].as<std::string>(), "none");
  EXPECT_EQ(b.metadata["device"]["colour"].as<std::string>(), "blue");
  EXPECT_EQ(b.metadata["truth"]["note"].as<std::string>(), "simulated");
  // Shots with extra columns (quoted comma kept) and images copied.
  ASSERT_EQ(b.shots.size(), 2u);
  EXPECT_EQ(b.shot_extra_columns, (std::vector<std::string>{"placement", "comment"}));
  EXPECT_EQ(b.shots[0].extra, (std::vector<std::string>{"hor_0_90", "first, with comma"}));
  EXPECT_EQ(b.shots[0].exposure_s, 0.01);
  EXPECT_FALSE(b.shots[1].exposure_s.has_value());
  EXPECT_EQ(io::read_text(out / "images" / "b.png"), "PNG bytes");
  // Truth, with its NaN rows.
  ASSERT_TRUE(b.truth_orientation.has_value());
  EXPECT_EQ(b.truth_world, "enu-magnetic");
  EXPECT_TRUE(std::isnan(b.truth_orientation->values(1, 0)));
  EXPECT_EQ(b.truth_orientation->values(0, 0), 1.0);
  // Other files copied as they were.
  EXPECT_EQ(b.other_files, (std::vector<fs::path>{"board.yaml", "truth/scene.yaml"}));
  EXPECT_EQ(io::read_text(out / "board.yaml"), io::read_text(in / "board.yaml"));
  // And a second generation is byte-identical to the first.
  const fs::path out2 = dir / "out2";
  write_capture(b, out2);
  for (const char* f : {"capture.yaml", "sensors/accelerometer.csv", "sensors/gyroscope.csv.gz", "shots.csv", "truth/orientation.csv.gz"})
    EXPECT_EQ(io::read_text(out2 / f), io::read_text(out / f)) << f;
}

TEST(CaptureRoundTrip, SensorLoggerToNativeToNative) {
  Diagnostics d;
  const Capture a = import_capture(test::shared_path("data/phone-logs/android-sensorlogger-walk"), d);
  TempDir dir;
  write_capture(a, dir / "n1");
  Diagnostics d1;
  const Capture b = import_capture(dir / "n1", d1);
  write_capture(b, dir / "n2");
  Diagnostics d2;
  const Capture c = read_capture(dir / "n2", d2);
  ASSERT_EQ(a.streams.size(), c.streams.size());
  for (const auto& [name, s] : a.streams) expect_streams_identical(s, c.require(name));
  EXPECT_EQ(c.time_origin, a.time_origin);
  EXPECT_EQ(c.device_model, "22041211AC");
  EXPECT_EQ(c.metadata["source"]["format"].as<std::string>(), "sensor-logger");
  EXPECT_TRUE(d2.empty());
}

TEST(CaptureErrors, MissingCaptureYaml) {
  TempDir dir;
  write_file(dir / "sensors" / "accelerometer.csv", "t,x,y,z\n0,0,0,9.8\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("capture.yaml: missing: not an antpose capture folder"));
  EXPECT_THAT(error_of(dir / "nope"), HasSubstr("capture folder not found"));
}

TEST(CaptureErrors, UnreadableFile) {
  TempDir dir;
  write_minimal(dir.path());
  fs::create_directories(dir / "sensors" / "pressure.csv");  // a folder where a file is expected is ignored
  EXPECT_EQ(error_of(dir.path()), "(no error)");
  EXPECT_THROW(io::read_text(dir / "sensors" / "pressure.csv"), InputError);
  try {
    io::read_text(dir / "missing.csv");
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("missing.csv: file not found"));
  }
  if (::geteuid() != 0) {  // root reads everything
    fs::permissions(dir / "sensors" / "gyroscope.csv", fs::perms::none);
    EXPECT_THAT(error_of(dir.path()), HasSubstr("gyroscope.csv: cannot open for reading"));
    fs::permissions(dir / "sensors" / "gyroscope.csv", fs::perms::owner_all);
  }
}

TEST(CaptureErrors, MalformedNumberNamesFileLineColumn) {
  TempDir dir;
  write_minimal(dir.path());
  write_file(dir / "sensors" / "gyroscope.csv", "t,x,y,z\n0,0,0,0\n\n0.01,0,1.2.3,0\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("gyroscope.csv:4: column 'y': '1.2.3' is not a number"));
}

TEST(CaptureErrors, NanInSensorStream) {
  TempDir dir;
  write_minimal(dir.path());
  write_file(dir / "sensors" / "gyroscope.csv", "t,x,y,z\n0,0,0,0\n0.01,0,nan,0\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("gyroscope.csv:3: column 'y': 'nan' is not a finite number"));
  write_file(dir / "sensors" / "gyroscope.csv", "t,x,y,z\n0,0,0,0\n0.01,0,0,-inf\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("gyroscope.csv:3: column 'z': '-inf' is not a finite number"));
  // In memory (importers, simulators): caught by validate_capture.
  Capture c;
  c.streams.emplace("gyroscope", Stream::vector3("gyroscope", {0.0, 0.01}, {Vec3(0, 0, 0), Vec3(0, NAN, 0)}));
  Diagnostics d;
  try {
    validate_capture(c, dir / "mem", d);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("sensors/gyroscope.csv:3: column 'y': nan is not a finite number"));
  }
}

TEST(CaptureErrors, EmptyStream) {
  TempDir dir;
  write_minimal(dir.path());
  write_file(dir / "sensors" / "magnetometer.csv", "t,x,y,z\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("magnetometer.csv: no samples: the magnetometer stream is empty"));
  write_file(dir / "sensors" / "magnetometer.csv", "");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("magnetometer.csv: empty file, expected a CSV header line"));
}

TEST(CaptureErrors, TimeBackwardsAndRepeatedNameTheLine) {
  TempDir dir;
  write_minimal(dir.path());
  // The blank line makes the row index differ from the line number: the message must use the line.
  write_file(dir / "sensors" / "gyroscope.csv", "t,x,y,z\n0,0,0,0\n\n0.02,0,0,0\n0.01,0,0,0\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("gyroscope.csv:5: t = 0.01 goes backwards (previous row has t = 0.02)"));
  write_file(dir / "sensors" / "gyroscope.csv", "t,x,y,z\n0,0,0,0\n0.01,0,0,0\n\n\n0.01,1,0,0\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("gyroscope.csv:6: t = 0.01 repeats the previous row's time"));
}

TEST(CaptureWarnings, LargeGapNamesTheLine) {
  TempDir dir;
  write_minimal(dir.path());
  std::string gyr = "t,x,y,z\n";
  for (int i = 0; i < 50; ++i) gyr += fmt::format("{},0,0,0\n", i * 0.01);
  gyr += "\n";
  for (int i = 0; i < 50; ++i) gyr += fmt::format("{},0,0,0\n", 2.0 + i * 0.01);
  write_file(dir / "sensors" / "gyroscope.csv", gyr);
  Diagnostics d;
  read_capture(dir.path(), d);
  ASSERT_EQ(d.warnings().size(), 1u);
  EXPECT_THAT(d.warnings()[0].to_string(), HasSubstr("gyroscope.csv:53: gap of 1.510 s in the stream before t = 2"));
}

TEST(CaptureWarnings, ShotOutsideSensorSpanAndMissingImage) {
  TempDir dir;
  write_minimal(dir.path());
  write_file(dir / "images" / "a.jpg", "x");
  write_file(dir / "images" / "b.jpg", "x");
  write_file(dir / "shots.csv", "index,t,image\n0,0.5,images/a.jpg\n\n1,7.5,images/b.jpg\n");
  Diagnostics d;
  read_capture(dir.path(), d);
  ASSERT_EQ(d.warnings().size(), 1u);
  EXPECT_THAT(d.warnings()[0].to_string(), HasSubstr("shots.csv:4: shot 1 at t = 7.5 s lies outside the sensor data"));
  write_file(dir / "shots.csv", "index,t,image\n0,0.5,images/a.jpg\n1,0.7,images/missing.jpg\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("shots.csv:3: image 'images/missing.jpg' not found"));
}

TEST(CaptureStreams, VectorColumnsAreTakenByNameInAnyOrder) {
  TempDir dir;
  write_minimal(dir.path());
  write_file(dir / "sensors" / "magnetometer.csv",
             "t,z,temp,y,x\n0,25,31.5,-30,20\n0.5,26,31.5,-31,21\n1,25,31.6,-30,20\n");
  Diagnostics d;
  const Capture c = read_capture(dir.path(), d);
  const Stream& mag = c.require("magnetometer");
  ASSERT_TRUE(mag.has_xyz());
  EXPECT_EQ(mag.columns, (std::vector<std::string>{"x", "y", "z", "temp"}));
  EXPECT_EQ(mag.xyz(1), Vec3(21, -31, 26));
  write_file(dir / "sensors" / "magnetometer.csv", "t,x,z\n0,20,25\n1,20,25\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("magnetometer.csv:1: no column 'y': the magnetometer stream has the "
                                              "columns t,x,z (expected t,x,y,z; extra columns are allowed)"));
}

TEST(CaptureErrors, AnImagePathThatIsAFolderOrLeadsOutIsSaidSo) {
  TempDir dir;
  write_minimal(dir.path());
  std::filesystem::create_directories(dir / "images" / "b.jpg");
  write_file(dir / "shots.csv", "index,t,image\n0,0.5,images/b.jpg\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("shots.csv:2: image 'images/b.jpg' is a folder, expected a photo file"));
  write_file(dir / "shots.csv", "index,t,image\n0,0.5,/etc/hostname\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("shots.csv:2: image '/etc/hostname' is an absolute path"));
  write_file(dir / "shots.csv", "index,t,image\n0,0.5,images/a.jpg\n1,0.6,images/./a.jpg\n");
  write_file(dir / "images" / "a.jpg", "x");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("shots.csv:3: image 'images/./a.jpg' is listed again (first on line 2)"));
  write_file(dir / "shots.csv", "index,t,image\n0,0.5,images/../../x.jpg\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("image 'images/../../x.jpg' leads out of the capture folder"));
}

TEST(CaptureUnits, AccelerometerInGIsConvertedOrRefused) {
  TempDir dir;
  write_minimal(dir.path());
  write_file(dir / "sensors" / "accelerometer.csv", "t,x,y,z\n0,0,0,1\n0.01,0,0.01,1\n0.02,0,0,1.01\n");
  Diagnostics d;
  const Capture c = read_capture(dir.path(), d);
  EXPECT_DOUBLE_EQ(c.require("accelerometer").values(0, 2), 9.80665);
  ASSERT_EQ(d.warnings().size(), 1u);
  EXPECT_THAT(d.warnings()[0].to_string(), HasSubstr("accelerometer.csv: median magnitude 1 looks like g: converted to m/s^2"));
  CaptureReadOptions strict;
  strict.repair_units = false;
  EXPECT_THAT(error_of(dir.path(), strict), HasSubstr("looks like g, expected m/s^2; unit repair is disabled (--no-unit-repair)"));
}

TEST(CaptureUnits, MagnetometerInGaussAndNanotesla) {
  TempDir dir;
  write_minimal(dir.path());
  CaptureReadOptions strict;
  strict.repair_units = false;
  write_file(dir / "sensors" / "magnetometer.csv", "t,x,y,z\n0,0.2,-0.3,0.25\n0.01,0.2,-0.3,0.25\n");
  Diagnostics d;
  EXPECT_DOUBLE_EQ(read_capture(dir.path(), d).require("magnetometer").values(0, 0), 20.0);
  EXPECT_TRUE(d.mentions("looks like gauss: converted to µT (×100)"));
  EXPECT_THAT(error_of(dir.path(), strict), HasSubstr("looks like gauss, expected µT; unit repair is disabled"));
  write_file(dir / "sensors" / "magnetometer.csv", "t,x,y,z\n0,20000,-30000,25000\n0.01,20000,-30000,25000\n");
  Diagnostics d2;
  EXPECT_DOUBLE_EQ(read_capture(dir.path(), d2).require("magnetometer").values(0, 1), -30.0);
  EXPECT_TRUE(d2.mentions("looks like nT: converted to µT (×0.001)"));
  EXPECT_THAT(error_of(dir.path(), strict), HasSubstr("looks like nT, expected µT"));
}

TEST(CaptureErrors, UnknownFormatVersionKind) {
  TempDir dir;
  write_minimal(dir.path(), "format: other-thing\nversion: 1\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("capture.yaml:1: unknown format 'other-thing', expected 'antpose-capture'"));
  write_minimal(dir.path(), "format: antpose-capture\nversion: 7\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("capture.yaml:2: format version 7 is not supported; this antpose reads versions 1 to 1"));
  write_minimal(dir.path(), "format: antpose-capture\nversion: 1\nkind: selfie\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("capture.yaml:3: kind 'selfie' is unknown; expected one of"));
  write_minimal(dir.path(), "format: antpose-capture\nversion: 1\ntime_origin: yesterday\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("capture.yaml:3: time_origin 'yesterday' is not an ISO-8601 UTC instant"));
}

TEST(CaptureErrors, BadSite) {
  TempDir dir;
  write_minimal(dir.path(), std::string(kYaml) + "site:\n  lat_deg: 95\n  lon_deg: 10\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("capture.yaml:5: site.lat_deg = 95 is out of range, expected [-90, 90]"));
  write_minimal(dir.path(), std::string(kYaml) + "site:\n  lat_deg: 45\n  lon_deg: 10\n  date: 2024-13-01\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("capture.yaml:7: site.date '2024-13-01' is not a date, expected YYYY-MM-DD"));
  write_minimal(dir.path(), std::string(kYaml) + "site:\n  lat_deg: north\n  lon_deg: 10\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("capture.yaml:5: 'site.lat_deg' is 'north', expected a number"));
}

TEST(CaptureRoundTrip, GzipStreamReadsLikePlain) {
  TempDir dir;
  write_minimal(dir.path());
  Diagnostics d;
  const Capture plain = read_capture(dir.path(), d);
  const std::string text = io::read_text(dir / "sensors" / "gyroscope.csv");
  fs::remove(dir / "sensors" / "gyroscope.csv");
  io::write_text_atomic(dir / "sensors" / "gyroscope.csv.gz", text);
  const Capture gz = read_capture(dir.path(), d);
  EXPECT_TRUE(gz.require("gyroscope").gzip);
  expect_streams_identical(plain.require("gyroscope"), gz.require("gyroscope"));
}

TEST(CaptureErrors, TruncatedAndMislabelledGzip) {
  TempDir dir;
  write_minimal(dir.path());
  fs::remove(dir / "sensors" / "gyroscope.csv");
  std::string gyr = "t,x,y,z\n";
  for (int i = 0; i < 2000; ++i) gyr += fmt::format("{},0.{},0,0\n", i * 0.01, i);
  const fs::path gz = dir / "sensors" / "gyroscope.csv.gz";
  io::write_text_atomic(gz, gyr);
  fs::resize_file(gz, fs::file_size(gz) / 2);
  EXPECT_THAT(error_of(dir.path()), HasSubstr("gyroscope.csv.gz: corrupt or truncated gzip data"));
  write_file(gz, gyr);  // plain text under a .gz name
  EXPECT_THAT(error_of(dir.path()), HasSubstr("gyroscope.csv.gz: corrupt gzip data: the file has a .gz name but no gzip header"));
}

TEST(CaptureErrors, DuplicatedStream) {
  TempDir dir;
  write_minimal(dir.path());
  io::write_text_atomic(dir / "sensors" / "gyroscope.csv.gz", "t,x,y,z\n0,0,0,0\n");
  EXPECT_THAT(error_of(dir.path()), HasSubstr("gyroscope.csv.gz: stream 'gyroscope' is stored twice (both .csv and .csv.gz)"));
}

TEST(CaptureWrite, RefusesExistingFolderAndLeavesItIntact) {
  TempDir dir;
  write_minimal(dir / "a");
  Diagnostics d;
  const Capture c = read_capture(dir / "a", d);
  write_file(dir / "b" / "precious.txt", "keep me");
  try {
    write_capture(c, dir / "b");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("already exists"));
  }
  EXPECT_EQ(io::read_text(dir / "b" / "precious.txt"), "keep me");
  EXPECT_FALSE(fs::exists(dir / "b" / "capture.yaml"));
  // No temporary folders left next to it.
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir.path())) ++entries;
  EXPECT_EQ(entries, 2u);
}

TEST(CaptureWrite, ClearedFieldsDoNotComeBackFromOldMetadata) {
  TempDir dir;
  write_minimal(dir / "a", std::string(kYaml) + "time_origin: 2020-01-01T00:00:00Z\nsite:\n  lat_deg: 1\n  lon_deg: 2\n");
  Diagnostics d;
  Capture c = read_capture(dir / "a", d);
  c.time_origin.reset();
  c.site.reset();
  write_capture(c, dir / "b");
  const Capture b = read_capture(dir / "b", d);
  EXPECT_FALSE(b.time_origin.has_value());
  EXPECT_FALSE(b.site.has_value());
}

}  // namespace
}  // namespace antpose
