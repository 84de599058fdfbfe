// Importers on the real phone-logger exports (../shared/data/phone-logs, README checks) and on a
// thesis collection-app project written by the test.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <fmt/format.h>

#include "antpose/io/import.hpp"
#include "antpose/io/time.hpp"
#include "support/test_support.hpp"

namespace antpose {
namespace {

namespace fs = std::filesystem;
using test::shared_path;
using test::TempDir;
using test::write_file;
using ::testing::HasSubstr;

double mean_norm(const Stream& s) {
  double sum = 0.0;
  for (std::size_t i = 0; i < s.size(); ++i) sum += s.xyz(i).norm();
  return sum / static_cast<double>(s.size());
}

std::string source_text(const Capture& c) {
  YAML::Emitter e;
  e << c.metadata["source"];
  return e.c_str();
}

TEST(ImportSensorLogger, RealAndroidWalkMatchesReadme) {
  const fs::path in = shared_path("data/phone-logs/android-sensorlogger-walk");
  EXPECT_EQ(detect_capture_format(in), CaptureFormat::kSensorLogger);
  Diagnostics d;
  const Capture c = import_capture(in, d);
  const Stream& acc = c.require("accelerometer");
  const Stream& gyr = c.require("gyroscope");
  const Stream& mag = c.require("magnetometer");
  EXPECT_EQ(acc.size(), 2908u);
  EXPECT_EQ(gyr.size(), 2908u);
  EXPECT_EQ(mag.size(), 1402u);
  // First accelerometer row is 1711523595018936600 ns, the earliest sample: t = 0 exactly there.
  ASSERT_TRUE(c.time_origin.has_value());
  EXPECT_EQ(*c.time_origin, "2024-03-27T07:13:15.018936600Z");
  EXPECT_EQ(io::parse_utc_iso8601(*c.time_origin), 1711523595018936600LL);
  EXPECT_EQ(acc.t.front(), 0.0);
  // Magnetometer first row 1711523595029761800 ns: 10 825 200 ns after the origin, to the ns.
  EXPECT_NEAR(mag.t.front(), 0.0108252, 1e-15);
  EXPECT_EQ(c.device_model, "22041211AC");
  EXPECT_EQ(c.device_id, "1f3d8ec0-f825-4166-afb2-284d61f74254");
  EXPECT_EQ(c.metadata["source"]["metadata"]["appVersion"].as<std::string>(), "1.27.1");
  // Specific force = Accelerometer (linear) + Gravity: |a| mean 9.871 m/s^2 per the README.
  EXPECT_NEAR(mean_norm(acc), 9.871, 0.01);
  EXPECT_NEAR(mean_norm(c.require("gravity")), 9.8067, 0.001);
  const double m = mean_norm(mag);
  EXPECT_GT(m, 20.0);
  EXPECT_LT(m, 70.0);
  EXPECT_NEAR(m, 52.3, 0.5);
  // Column order z,y,x in the file: the first row's x is the last field.
  EXPECT_NEAR(gyr.xyz(0).x(), -0.010999999940395355, 1e-18);
  EXPECT_NEAR(gyr.xyz(0).z(), 0.0038499999791383743, 1e-18);
  EXPECT_TRUE(c.find("rotation_vector"));
  EXPECT_EQ(c.require("rotation_vector").columns, (std::vector<std::string>{"qw", "qx", "qy", "qz"}));
  const std::string src = source_text(c);
  EXPECT_THAT(src, HasSubstr("Accelerometer + Gravity"));
  EXPECT_THAT(src, HasSubstr("Pedometer.csv"));
  EXPECT_THAT(src, HasSubstr("Location.csv: empty file"));
  EXPECT_TRUE(d.mentions("empty (no GPS fix recorded)"));
  // Two of the rows of Gravity.csv are 300 ns off the accelerometer's: reported, interpolated.
  EXPECT_TRUE(d.mentions("2 of 2908 time stamps differ, by up to 300 ns"));
}

TEST(ImportPhyphox, RealClimbingAllThreeSensors) {
  const fs::path in = shared_path("data/phone-logs/phyphox-climbing");
  EXPECT_EQ(detect_capture_format(in), CaptureFormat::kPhyphox);
  Diagnostics d;
  const Capture c = import_capture(in, d);
  EXPECT_EQ(c.require("accelerometer").size(), 1127u);
  EXPECT_EQ(c.require("gyroscope").size(), 1122u);
  EXPECT_EQ(c.require("magnetometer").size(), 1122u);
  EXPECT_EQ(c.require("pressure").size(), 236u);
  EXPECT_EQ(c.require("accelerometer").t.front(), 2.594975001E-2);
  EXPECT_EQ(c.require("gyroscope").t.front(), 1.920097500E-1);
  EXPECT_EQ(c.require("gyroscope").values(0, 0), -3.035070002E-2);
  EXPECT_EQ(c.require("pressure").t.front(), -5.148110000E-1);
  EXPECT_DOUBLE_EQ(c.require("pressure").values(0, 0), 1.017604446E3 * 100.0);  // hPa → Pa
  ASSERT_TRUE(c.time_origin.has_value());
  EXPECT_EQ(*c.time_origin, "2023-06-07T12:50:49.762457Z");
  EXPECT_EQ(c.device_model, "iPhone10,5");
  EXPECT_NEAR(mean_norm(c.require("accelerometer")), 9.93, 0.02);
  EXPECT_NEAR(mean_norm(c.require("magnetometer")), 45.7, 0.3);
  const std::string src = source_text(c);
  EXPECT_THAT(src, HasSubstr("Proximity.csv"));
  EXPECT_THAT(src, HasSubstr("−9.81"));
  EXPECT_TRUE(d.empty()) << d.warnings().front().to_string();
}

TEST(ImportPhyphox, RealWalkPocketWithoutStartEvent) {
  const fs::path in = shared_path("data/phone-logs/phyphox-walk-pocket");
  Diagnostics d;
  const Capture c = import_capture(in, d);
  EXPECT_EQ(c.require("accelerometer").size(), 3016u);
  EXPECT_EQ(c.require("gyroscope").size(), 3016u);
  EXPECT_EQ(c.require("accelerometer").t.front(), 1.732875011E-3);
  EXPECT_FALSE(c.find("magnetometer"));
  EXPECT_FALSE(c.time_origin.has_value());
  EXPECT_TRUE(d.mentions("no START event: the export has no wall-clock time"));
  EXPECT_EQ(c.device_model, "iPhone13,2");
  EXPECT_NEAR(mean_norm(c.require("accelerometer")), 9.8, 4.0);  // walking in a pocket: |a| swings widely
  EXPECT_THAT(source_text(c), HasSubstr("Location.csv"));
}

TEST(ImportPhyphox, UnknownUnitIsAnError) {
  TempDir dir;
  write_file(dir / "Accelerometer.csv", "\"Time (s)\",\"X (furlong/fortnight^2)\",\"Y (m/s^2)\",\"Z (m/s^2)\"\n0.1,1,2,9\n");
  Diagnostics d;
  try {
    import_capture(dir.path(), d);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("Accelerometer.csv:1"));
    EXPECT_THAT(e.what(), HasSubstr("unknown unit 'furlong/fortnight^2'"));
    EXPECT_THAT(e.what(), HasSubstr("m/s^2"));
  }
}

TEST(ImportPhyphox, ConvertsMilliteslaAndDegreesPerSecond) {
  TempDir dir;
  write_file(dir / "Gyroscope.csv", "\"Time (s)\",\"X (deg/s)\",\"Y (deg/s)\",\"Z (deg/s)\"\n0.1,180,0,0\n0.2,0,90,0\n");
  write_file(dir / "Magnetometer.csv", "\"Time (s)\",\"X (mT)\",\"Y (mT)\",\"Z (mT)\"\n0.1,0.02,0,-0.04\n0.2,0.02,0,-0.04\n");
  Diagnostics d;
  const Capture c = import_phyphox(dir.path(), d);
  EXPECT_NEAR(c.require("gyroscope").values(0, 0), std::numbers::pi, 1e-15);
  EXPECT_NEAR(c.require("magnetometer").values(0, 2), -40.0, 1e-12);
  EXPECT_TRUE(d.mentions("meta/time.csv") || !d.empty());
}

TEST(ImportSensorLogger, LinearAccelerationWithoutGravityIsRefused) {
  TempDir dir;
  write_file(dir / "Metadata.csv", "version,device name,platform,device id\n3,Test,android,x1\n");
  write_file(dir / "Accelerometer.csv", "time,seconds_elapsed,z,y,x\n1000000000,0,0.1,0.0,0.0\n1010000000,0.01,0.1,0.1,0\n");
  Diagnostics d;
  try {
    import_capture(dir.path(), d);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("Accelerometer.csv"));
    EXPECT_THAT(e.what(), HasSubstr("linear acceleration"));
    EXPECT_THAT(e.what(), HasSubstr("Gravity.csv"));
  }
}

TEST(ImportSensorLogger, BadTimeNamesFileLineAndColumn) {
  TempDir dir;
  write_file(dir / "Metadata.csv", "version,device name,platform\n3,Test,android\n");
  write_file(dir / "Gyroscope.csv", "time,seconds_elapsed,z,y,x\n1000000000,0,0.1,0.0,0.0\n\n10x0000000,0.01,0.1,0.1,0\n");
  Diagnostics d;
  try {
    import_capture(dir.path(), d);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("Gyroscope.csv:4: column 'time': '10x0000000' is not an integer"));
  }
}

// --- thesis collection-app project ---------------------------------------------------------

std::string frame_xml(double utc, double x, double y, double z, int index) {
  return fmt::format("      <Frame><Value><w>0.0</w><x>{}</x><y>{}</y><z>{}</z></Value><index>{}</index><time>{:.17g}</time></Frame>\n", x,
                     y, z, index, utc);
}

// sensor_N.xml with channels a (100 Hz), m and g over [t0, t1).
std::string sensor_xml(double t0, double t1, double disagree_at = -1) {
  std::string out = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<threads><thread><channels>\n";
  for (const char* ch : {"a", "m", "g"}) {
    out += fmt::format("  <channel>\n    <name>{}</name>\n    <frames>\n", ch);
    int k = 0;
    for (int i = static_cast<int>(std::lround(t0 * 100)); i < static_cast<int>(std::lround(t1 * 100)); ++i) {
      const double utc = 1388835284.0 + i * 0.01;
      double x = 0.1 * std::sin(i * 0.1), y = 9.8, z = 0.3;
      if (ch[0] == 'm') { x = 20.0; y = -30.0; z = 25.0 + 0.01 * i; }
      if (ch[0] == 'g') { x = 0.01 * i; y = 0.0; z = -0.01; }
      if (ch[0] == 'a' && std::abs(i * 0.01 - disagree_at) < 1e-9) x += 0.5;
      out += frame_xml(utc, x, y, z, k++);
    }
    out += "    </frames>\n  </channel>\n";
  }
  return out + "</channels></thread></threads>\n";
}

void write_thesis_project(const fs::path& dir, bool with_sensor_2 = true) {
  // Three collections; sensor files overlap by 0.5 s; sensor_1 disagrees with sensor_0 at 2.7 s.
  write_file(dir / "collection-proj.xml",
             "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
             "<Project>\n"
             "  <Name>test</Name>\n"
             "  <description>check that the data is written as expected</description>\n"
             "  <CREATETIME>1388835284.1</CREATETIME>\n"
             "  <unknownElement>ignored</unknownElement>\n"
             "  <Collections>\n"
             "    <collection>\n      <index>0</index>\n      <picture>pic_0.jpg</picture>\n      <sensor>sensor_0.xml</sensor>\n"
             "      <time>1388835285.5</time>\n    </collection>\n"
             "    <Collection>\n      <Index>1</Index>\n      <PICTURE>pic_1.jpg</PICTURE>\n      <Sensor>sensor_1.xml</Sensor>\n"
             "      <Time>1388835288.0</Time>\n    </Collection>\n"
             "    <collection>\n      <index>2</index>\n      <picture>pic_2.jpg</picture>\n      <sensor>sensor_2.xml</sensor>\n"
             "      <time>1388835290.5</time>\n    </collection>\n"
             "  </Collections>\n"
             "</Project>\n");
  write_file(dir / "sensor_0.xml", sensor_xml(0.0, 3.0));
  write_file(dir / "sensor_1.xml", sensor_xml(2.5, 5.5, 2.7));
  if (with_sensor_2) write_file(dir / "sensor_2.xml", sensor_xml(5.0, 8.0));
  for (int i = 0; i < 3; ++i) write_file(dir / fmt::format("pic_{}.jpg", i), "\xFF\xD8\xFF\xE0 not really a jpeg");
}

TEST(ImportThesis, MergesOverlapsDropsDuplicatesReportsDisagreement) {
  TempDir dir;
  write_thesis_project(dir.path());
  EXPECT_EQ(detect_capture_format(dir.path()), CaptureFormat::kThesisProject);
  Diagnostics d;
  const Capture c = import_capture(dir.path(), d);
  // 0 … 8 s at 100 Hz = 800 distinct frames per channel (the overlaps 2.5–3.0 and 5.0–5.5 merged).
  for (const char* name : {"accelerometer", "magnetometer", "gyroscope"}) EXPECT_EQ(c.require(name).size(), 800u) << name;
  const Stream& acc = c.require("accelerometer");
  for (std::size_t i = 1; i < acc.size(); ++i) ASSERT_GT(acc.t[i], acc.t[i - 1]);
  // Origin = earliest sample (1388835284.0): t exact to far below the µs.
  EXPECT_EQ(*c.time_origin, "2014-01-04T11:34:44.000000Z");
  EXPECT_EQ(acc.t.front(), 0.0);
  EXPECT_NEAR(acc.t[270], 2.7, 1e-6);
  EXPECT_NEAR(acc.t[270], io::seconds_since(1388835284.0 + 270 * 0.01, 1388835284000000000LL), 0.0);
  // The disagreeing frame keeps sensor_0's value (no +0.5) and is reported with both files and the time.
  EXPECT_NEAR(acc.values(270, 0), 0.1 * std::sin(27.0), 1e-12);
  ASSERT_EQ(d.warnings().size(), 1u) << d.warnings().front().to_string();
  const std::string w = d.warnings().front().to_string();
  EXPECT_THAT(w, HasSubstr("sensor_1.xml:"));
  EXPECT_THAT(w, HasSubstr("sensor_0.xml:"));
  EXPECT_THAT(w, HasSubstr("1388835286.7"));
  EXPECT_THAT(w, HasSubstr("kept the frame of sensor_0.xml"));
  // Shots: images/pic_N.jpg, sourced from the project folder.
  ASSERT_EQ(c.shots.size(), 3u);
  EXPECT_EQ(c.shots[1].index, 1);
  EXPECT_EQ(c.shots[1].image, "images/pic_1.jpg");
  EXPECT_EQ(c.shots[1].source, dir.path() / "pic_1.jpg");
  EXPECT_NEAR(c.shots[1].t, 4.0, 1e-9);
  const std::string src = source_text(c);
  EXPECT_THAT(src, HasSubstr("299 duplicate frames dropped, 1 disagreeing"));
  EXPECT_EQ(c.metadata["source"]["project"]["name"].as<std::string>(), "test");

  // Written and read back: images copied under images/.
  const fs::path out = dir / "native";
  write_capture(c, out);
  Diagnostics d2;
  const Capture back = read_capture(out, d2);
  EXPECT_TRUE(fs::is_regular_file(out / "images" / "pic_2.jpg"));
  EXPECT_EQ(back.shots.size(), 3u);
  EXPECT_EQ(back.require("accelerometer").t, acc.t);
}

TEST(ImportThesis, MissingSensorFileNamesProjectLine) {
  TempDir dir;
  write_thesis_project(dir.path(), false);
  Diagnostics d;
  try {
    import_capture(dir.path(), d);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("collection-proj.xml:23"));
    EXPECT_THAT(e.what(), HasSubstr("sensor file 'sensor_2.xml' not found"));
  }
}

TEST(ImportThesis, MissingPictureNamesProjectLine) {
  TempDir dir;
  write_thesis_project(dir.path());
  fs::remove(dir / "pic_1.jpg");
  Diagnostics d;
  try {
    import_capture(dir.path(), d);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("collection-proj.xml:16"));
    EXPECT_THAT(e.what(), HasSubstr("picture 'pic_1.jpg' not found"));
  }
}

TEST(ImportThesis, MalformedXmlAndNumbersNameTheLine) {
  TempDir dir;
  write_thesis_project(dir.path());
  std::string s1 = sensor_xml(2.5, 5.5);
  s1.replace(s1.find("<x>"), 3, "<x>abc");
  write_file(dir / "sensor_1.xml", s1);
  Diagnostics d;
  try {
    import_capture(dir.path(), d);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("sensor_1.xml:6: column '<x>'"));
    EXPECT_THAT(e.what(), HasSubstr("is not a number"));
  }
  write_file(dir / "collection-proj.xml", "<Project>\n<collections>\n<collection>\n</Project>\n");
  try {
    import_capture(dir.path(), d);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("collection-proj.xml:4: not valid XML"));
  }
}

TEST(ImportCapture, UnknownLayoutListsAcceptedOnes) {
  TempDir dir;
  write_file(dir / "notes.txt", "hello");
  Diagnostics d;
  try {
    import_capture(dir.path(), d);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("not a capture antpose can read"));
    EXPECT_THAT(e.what(), HasSubstr("collection-proj.xml"));
    EXPECT_THAT(e.what(), HasSubstr("Sensor Logger"));
    EXPECT_THAT(e.what(), HasSubstr("phyphox"));
    EXPECT_THAT(e.what(), HasSubstr("capture.yaml"));
  }
}

}  // namespace
}  // namespace antpose
