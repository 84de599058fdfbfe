// antpose measure on bad input: every case names what is wrong and never prints a confident
// number it cannot support. One small simulated antenna capture serves all cases; the device
// profile is the simulator's truth (these tests check messages, not accuracy: that is the long
// acceptance test's job).
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <exiv2/exiv2.hpp>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "antpose/io/text_file.hpp"
#include "antpose/model/antenna_model.hpp"
#include "antpose/store/content_hash.hpp"
#include "antpose/version.hpp"
#include "support/test_support.hpp"

namespace antpose {
namespace {

namespace fs = std::filesystem;
using ::testing::AnyOf;
using ::testing::HasSubstr;
using ::testing::Not;

class MeasureCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir;
    const auto r = test::run_cli(fmt::format(
        "simulate capture -o '{}' --scenario antenna --distribution classic --seed 3 --setting rooftop --photos 6 "
        "--width 960 --height 720",
        capture().string()));
    ASSERT_EQ(r.status, 0) << r.err;
    // A device profile from the simulator's truth.
    const YAML::Node truth = YAML::LoadFile((capture() / "truth/device.yaml").string());
    YAML::Node profile;
    profile["format"] = "antpose-device";
    profile["version"] = 1;
    profile["device"]["id"] = "sim";
    profile["camera"] = truth["camera"];
    profile["camera_imu"]["R_device_camera"] = truth["camera_imu"]["R_device_camera"];
    profile["camera_imu"]["time_offset_s"] = truth["camera_imu"]["time_offset_s"];
    YAML::Emitter out;
    out << profile;
    test::write_file(device(), out.c_str());
    const YAML::Node scene = YAML::LoadFile((capture() / "truth/scene.yaml").string());
    const auto roi = scene["antennas"][0]["roi"];
    roi_image_ = roi["image"].as<std::string>();
    roi_ = fmt::format("{}:{},{},{},{}", roi_image_, roi["x"].as<int>(), roi["y"].as<int>(), roi["width"].as<int>(),
                       roi["height"].as<int>());
    model_ = scene["antennas"][0]["model"].as<std::string>();
  }
  static void TearDownTestSuite() { delete dir_; }

  static fs::path capture() { return *dir_ / "site"; }
  static fs::path device() { return *dir_ / "phone.yaml"; }
  static std::string measure(const fs::path& cap, const std::string& rest) {
    return fmt::format("measure '{}' --device '{}' {}", cap.string(), device().string(), rest);
  }
  // A copy of the capture to damage.
  static fs::path copy(const std::string& name) {
    const fs::path to = *dir_ / name;
    fs::remove_all(to);
    fs::copy(capture(), to, fs::copy_options::recursive);
    return to;
  }

  static inline test::TempDir* dir_ = nullptr;
  static inline std::string roi_, roi_image_, model_;
};

TEST_F(MeasureCli, RoiOnTheSkyFailsThatAntennaWithItsReason) {
  const auto json = *dir_ / "sky.json";
  const auto r = test::run_cli(
      measure(capture(), fmt::format("--model {} --roi {}:0,0,60,60 --json '{}'", model_, roi_image_, json.string())));
  EXPECT_EQ(r.status, 3) << r.out << r.err;
  EXPECT_THAT(r.out, HasSubstr("FAILED"));
  const auto j = nlohmann::json::parse(io::read_text(json));
  ASSERT_EQ(j["antennas"].size(), 1u);
  EXPECT_TRUE(j["antennas"][0]["azimuth_magnetic_deg"].is_null());
  EXPECT_TRUE(j["antennas"][0]["verdict"].is_null());  // a refusal is no "unique" answer
  // Whether a box of the model can span so small a rectangle at all (a panel far away) or not,
  // the refusal says that no pose fits, and asks for the rectangle and the model.
  const auto error = j["antennas"][0]["error"].get<std::string>();
  EXPECT_THAT(error, AnyOf(HasSubstr("nothing in the rectangle fits the outline of the model"),
                           HasSubstr("fits its outline in the photos and spans the rectangle")));
  EXPECT_THAT(error, HasSubstr("is the model this antenna's?"));
}

TEST_F(MeasureCli, TheBenchmarkScoresWhatMeasureAnswers) {
  // `bench measure` runs the measurement of `measure` on the truth's rectangles and models: its
  // errors are that answer less the truth, and its stages are the measurement's.
  const auto json = *dir_ / "answer.json";
  const auto bench_json = *dir_ / "bench.json";
  test::run_cli(measure(capture(), fmt::format("--model {} --roi {} --json '{}'", model_, roi_, json.string())));
  const auto r = test::run_cli(fmt::format("bench measure '{}' --device '{}' --json '{}'", capture().string(),
                                           device().string(), bench_json.string()));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_THAT(r.out, HasSubstr("1 sites: median"));
  const auto answer = nlohmann::json::parse(io::read_text(json))["antennas"][0];
  const auto truth = YAML::LoadFile((capture() / "truth/scene.yaml").string())["antennas"][0];
  const auto site = nlohmann::json::parse(io::read_text(bench_json))["sites"][0];
  EXPECT_EQ(site["photos"], 6);
  EXPECT_GT(site["seconds"].get<double>(), 0.0);
  for (const char* stage : {"board poses", "dense stereo", "registration"})
    EXPECT_TRUE(site["stage_seconds"].contains(stage)) << stage << " in " << site["stage_seconds"];
  ASSERT_EQ(site["antennas"].size(), 1u);
  const auto scored = site["antennas"][0];
  ASSERT_TRUE(scored["refused"].is_null()) << scored["refused"];
  EXPECT_EQ(scored["verdict"], answer["verdict"]);
  const double azimuth = answer["azimuth_magnetic_deg"].get<double>() - truth["azimuth_magnetic_deg"].as<double>();
  EXPECT_NEAR(scored["azimuth_error_deg"].get<double>(), std::remainder(azimuth, 360.0), 1e-6);
  EXPECT_NEAR(scored["downtilt_error_deg"].get<double>(),
              answer["downtilt_deg"].get<double>() - truth["downtilt_deg"].as<double>(), 1e-6);
  EXPECT_NEAR(scored["azimuth_sigma_deg"].get<double>(), answer["sigma"]["azimuth_magnetic_deg"].get<double>(), 1e-6);
  // The σ's budget: one share per source, their squares adding up to each angle's σ².
  const auto& budget = answer["sigma_budget"];
  ASSERT_GE(budget.size(), 3u) << budget;
  EXPECT_EQ(budget[0]["source"], "board attitude in the world");
  for (const char* angle : {"azimuth_magnetic_deg", "downtilt_deg", "roll_deg"}) {
    double sum = 0.0;
    for (const auto& share : budget) sum += std::pow(share[angle].get<double>(), 2);
    EXPECT_NEAR(std::sqrt(sum), answer["sigma"][angle].get<double>(), 1e-6) << angle << " in " << budget;
  }
}

TEST_F(MeasureCli, AnAntennaOverTheSigmaLimitIsWrittenAndExitsFour) {
  const auto r = test::run_cli(measure(
      capture(), fmt::format("--model {} --roi {} --max-sigma-deg 0.001 --json - --progress json", model_, roi_)));
  EXPECT_EQ(r.status, 4) << r.err;
  // Progress for a wrapper: one JSON object per line.
  const auto first = r.err.substr(0, r.err.find('\n'));
  EXPECT_EQ(nlohmann::json::parse(first)["stage"], "board poses") << first;
  EXPECT_THAT(r.err, HasSubstr("warning: antenna 1 is not usable: azimuth sigma"));
  EXPECT_THAT(r.err, HasSubstr("over --max-sigma-deg 0.001"));
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_FALSE(j["antennas"][0]["downtilt_deg"].is_null());  // written all the same
  // What produced it: this antpose, the capture and the device by content, the options given.
  const auto& p = j["provenance"];
  EXPECT_EQ(p["command"], "measure");
  EXPECT_THAT(p["antpose"].get<std::string>(), HasSubstr(std::string(kVersion)));
  EXPECT_EQ(p["inputs"][0]["role"], "capture");
  EXPECT_EQ(p["inputs"][0]["sha256"], store::content_digest(capture()));
  EXPECT_EQ(p["device"]["profile_sha256"].get<std::string>().size(), 64u);
  EXPECT_EQ(p["options"]["--max-sigma-deg"], "0.001");
  EXPECT_FALSE(p["site"].is_null());
}

TEST_F(MeasureCli, TheReportShowsWhatLimitsEachSigma) {
  const auto folder = *dir_ / "report";
  const auto r = test::run_cli(
      measure(capture(), fmt::format("--model {} --roi {} --report '{}'", model_, roi_, folder.string())));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_THAT(r.err, Not(HasSubstr("\r")));  // stderr is no terminal here: no progress line
  EXPECT_THAT(r.err, Not(HasSubstr("board poses")));
  const auto html = io::read_text(folder / "index.html");
  EXPECT_THAT(html, HasSubstr("<h2>Uncertainty budget</h2>"));
  EXPECT_THAT(html, HasSubstr("<h2>Provenance</h2>"));
  EXPECT_TRUE(nlohmann::json::parse(io::read_text(folder / "result.json")).contains("provenance"));
  for (const char* source : {"board attitude in the world", "outline noise", "camera poses"})
    EXPECT_THAT(html, HasSubstr(fmt::format("<td>{}</td>", source)));
}

TEST_F(MeasureCli, TheBenchmarkNamesACaptureWithoutTruth) {
  const auto cap = copy("no-truth");
  fs::remove(cap / "truth" / "scene.yaml");
  const auto r = test::run_cli(fmt::format("bench measure '{}' --device '{}'", cap.string(), device().string()));
  EXPECT_EQ(r.status, 2) << r.out << r.err;
  EXPECT_THAT(r.err, HasSubstr((cap / "truth" / "scene.yaml").string()));
}

TEST_F(MeasureCli, ARectangleTheAntennaFillsLittleOfIsNamed) {
  // A rectangle drawn loosely (1.4 times the antenna's about it) still measures it; one 2.6 times
  // as wide and tall, which the antenna fills to a seventh, names the rectangle: it was drawn
  // around more than this antenna.
  int x = 0, y = 0, w = 0, h = 0;
  ASSERT_EQ(std::sscanf(roi_.substr(roi_image_.size() + 1).c_str(), "%d,%d,%d,%d", &x, &y, &w, &h), 4);
  const auto around = [&](double factor, const char* name) {
    const int x0 = std::max(0, static_cast<int>(x - (factor - 1) / 2 * w));
    const int y0 = std::max(0, static_cast<int>(y - (factor - 1) / 2 * h));
    const int x1 = std::min(960, static_cast<int>(x + (factor + 1) / 2 * w));
    const int y1 = std::min(720, static_cast<int>(y + (factor + 1) / 2 * h));
    const auto json = *dir_ / name;
    test::run_cli(measure(capture(), fmt::format("--model {} --roi {}:{},{},{},{} --json '{}'", model_, roi_image_, x0,
                                                 y0, x1 - x0, y1 - y0, json.string())));
    return nlohmann::json::parse(io::read_text(json))["antennas"][0];
  };
  const auto loose = around(1.4, "loose.json");
  EXPECT_TRUE(loose["error"].is_null()) << loose["error"];
  const auto sloppy = around(2.6, "sloppy.json");
  ASSERT_FALSE(sloppy["error"].is_null());
  EXPECT_THAT(sloppy["error"].get<std::string>(), HasSubstr("is the rectangle drawn closely around the whole antenna"));
}

TEST_F(MeasureCli, PhotosWithoutTheBoardAreNamedAndLeftOut) {
  const auto cap = copy("no-board");
  // Two photos lose the board (a grey frame of the same size).
  for (const char* name : {"images/img_0001.jpg", "images/img_0004.jpg"})
    cv::imwrite((cap / name).string(), cv::Mat(720, 960, CV_8UC1, cv::Scalar(128)));
  const auto json = *dir_ / "no-board.json";
  const auto r =
      test::run_cli(measure(cap, fmt::format("--model {} --roi {} --json '{}'", model_, roi_, json.string())));
  EXPECT_THAT(r.err, HasSubstr("img_0001.jpg: photo skipped: no board found"));
  EXPECT_THAT(r.err, HasSubstr("img_0004.jpg: photo skipped"));
  const auto j = nlohmann::json::parse(io::read_text(json));
  EXPECT_EQ(j["photos"], 6);
  EXPECT_EQ(j["photos_with_board"], 4);
  EXPECT_EQ(j["skipped"].size(), 2u);

  // The board in only one photo: no measurement, and the reasons.
  for (const char* name : {"images/img_0000.jpg", "images/img_0002.jpg", "images/img_0003.jpg"})
    cv::imwrite((cap / name).string(), cv::Mat(720, 960, CV_8UC1, cv::Scalar(128)));
  const auto one = test::run_cli(measure(cap, fmt::format("--model {} --roi {}", model_, roi_)));
  EXPECT_EQ(one.status, 3);
  EXPECT_THAT(one.err, HasSubstr("the board was found in 1 of 6 photos; at least 2 are needed"));
}

TEST_F(MeasureCli, OnePhotoWhoseHeaderClaimsAnotherSizeIsRefusedAlone) {
  const auto cap = copy("huge-header");
  // The first photo (not the ROI's) becomes a small JPEG whose header claims 28800×21600 px: the
  // photos' aspect ratio, so that taken for the capture's size it would rescale the intrinsics and
  // every other photo would be refused.
  const std::string victim = roi_image_ == "images/img_0000.jpg" ? "images/img_0001.jpg" : "images/img_0000.jpg";
  test::write_file(cap / victim, test::jpeg_claiming(28800, 21600));
  const auto json = *dir_ / "huge-header.json";
  const auto r =
      test::run_cli(measure(cap, fmt::format("--model {} --roi {} --json '{}'", model_, roi_, json.string())));
  ASSERT_THAT(r.status, AnyOf(0, 4)) << r.err;
  EXPECT_THAT(r.err, HasSubstr(victim + ": photo skipped: image is 28800x21600 px but the intrinsics are for 960x720"));
  const auto j = nlohmann::json::parse(io::read_text(json));
  EXPECT_EQ(j["photos_with_board"], 5);
  EXPECT_EQ(j["photo_size_px"], nlohmann::json::array({960, 720}));
  EXPECT_TRUE(j["antennas"][0]["error"].is_null()) << j["antennas"][0]["error"];
}

TEST_F(MeasureCli, AWrongBoardSizeIsNamedWhereTheAntennaFails) {
  // A copy whose board.yaml gives `factor` times the printed square.
  const auto scaled = [](const std::string& name, double factor) {
    const auto cap = copy(name);
    YAML::Node board = YAML::LoadFile((cap / "board.yaml").string());
    const double square_m = factor * board["square_m"].as<double>();
    board["square_m"] = square_m;
    YAML::Emitter out;
    out << board;
    test::write_file(cap / "board.yaml", out.c_str());
    return std::pair{cap, fmt::format("{} m", square_m)};
  };
  // Half: the antenna's points span half the model.
  const auto [half, half_m] = scaled("half-board", 0.5);
  auto r = test::run_cli(measure(half, fmt::format("--model {} --roi {}", model_, roi_)));
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_THAT(r.out, HasSubstr("if the board's square_m (" + half_m + " in board.yaml) or the model's size is wrong"));
  // Ten times: by the board the phone was carried at a run, whatever the antenna's reason.
  const auto [tenfold, tenfold_m] = scaled("tenfold-board", 10.0);
  r = test::run_cli(measure(tenfold, fmt::format("--model {} --roi {}", model_, roi_)));
  EXPECT_EQ(r.status, 3) << r.err;
  EXPECT_THAT(r.err, HasSubstr("faster than a person framing photos walks (limit 3.0 m/s): check square_m (" +
                               tenfold_m + " in board.yaml)"));
  EXPECT_THAT(r.out, HasSubstr("the board's scale is in doubt (see the warning on square_m)"));
}

// Phone photos stored in the sensor's pixels with an EXIF turn: the rectangle is drawn on the photo
// shown upright, and the measurement equals the untagged one's.
TEST_F(MeasureCli, PhotosWithAnExifTurnMeasureAsUntagged) {
  const auto angles = [](const nlohmann::json& j) {
    const auto& a = j["antennas"][0];
    return std::array{a["azimuth_magnetic_deg"].get<double>(), a["downtilt_deg"].get<double>(),
                      a["roll_deg"].get<double>()};
  };
  const auto plain_json = *dir_ / "untagged.json";
  auto r = test::run_cli(
      measure(capture(), fmt::format("--model {} --roi {} --json '{}'", model_, roi_, plain_json.string())));
  ASSERT_THAT(r.status, AnyOf(0, 4)) << r.err;
  const auto plain = angles(nlohmann::json::parse(io::read_text(plain_json)));
  int x = 0, y = 0, w = 0, h = 0;
  ASSERT_EQ(std::sscanf(roi_.substr(roi_.rfind(':') + 1).c_str(), "%d,%d,%d,%d", &x, &y, &w, &h), 4);
  const int W = 960, H = 720;
  for (const int orientation : {6, 8}) {
    const auto cap = copy(fmt::format("exif-{}", orientation));
    for (const auto& entry : fs::directory_iterator(cap / "images")) {
      auto image = Exiv2::ImageFactory::open(entry.path().string());
      image->readMetadata();
      image->exifData()["Exif.Image.Orientation"] = static_cast<std::uint16_t>(orientation);
      image->writeMetadata();
    }
    // The rectangle on the photo turned upright (io/exif_orientation.hpp): 6 turns it clockwise.
    const auto upright = orientation == 6 ? fmt::format("{},{},{},{}", H - y - h, x, h, w)
                                          : fmt::format("{},{},{},{}", y, W - x - w, h, w);
    const auto json = *dir_ / fmt::format("exif-{}.json", orientation);
    const auto report = *dir_ / fmt::format("exif-{}-report", orientation);
    r = test::run_cli(measure(cap, fmt::format("--model {} --roi {}:{} --json '{}' --report '{}'", model_, roi_image_,
                                               upright, json.string(), report.string())));
    ASSERT_THAT(r.status, AnyOf(0, 4)) << r.err;
    const auto j = nlohmann::json::parse(io::read_text(json));
    EXPECT_EQ(j["antennas"][0]["roi"]["exif_orientation"], orientation);
    const auto tagged = angles(j);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(tagged[k], plain[k], 1e-6) << orientation;
    // The report shows the photos upright.
    const cv::Mat overlay = cv::imread((report / "overlay_01.jpg").string());
    EXPECT_GT(overlay.rows, overlay.cols) << orientation;
  }
  // A rectangle that fits the stored photo but not the upright one is named as such.
  r = test::run_cli(measure(*dir_ / "exif-6", fmt::format("--model {} --roi {}:700,10,200,40", model_, roi_image_)));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("reaches outside the 720×960 image (as shown upright)"));
}

TEST_F(MeasureCli, PhotosAllFromOnePlaceGiveNoConfidentNumber) {
  const auto cap = copy("one-place");
  // Every shot is the ROI's photo at (nearly) its instant: one viewpoint, no baseline.
  std::string shots = "index,t,image\n";
  const auto lines = io::read_text(capture() / "shots.csv");
  const auto at = lines.find(roi_image_);
  const auto start = lines.rfind('\n', at) + 1;
  const double t = std::stod(lines.substr(lines.find(',', start) + 1));
  // Copies of the ROI's photo under other names: a photo listed twice is refused by the reader.
  for (int i = 0; i < 6; ++i) {
    const std::string name = i == 0 ? roi_image_ : fmt::format("images/again_{}.jpg", i);
    if (i > 0) fs::copy_file(cap / roi_image_, cap / name);
    shots += fmt::format("{},{},{}\n", i, t + 0.02 * i, name);
  }
  test::write_file(cap / "shots.csv", shots);
  const auto json = *dir_ / "one-place.json";
  const auto r =
      test::run_cli(measure(cap, fmt::format("--model {} --roi {} --json '{}'", model_, roi_, json.string())));
  EXPECT_THAT(r.err, HasSubstr("all photos were taken from nearly one direction"));
  EXPECT_EQ(r.status, 3) << r.out << r.err;
  const auto j = nlohmann::json::parse(io::read_text(json));
  EXPECT_TRUE(j["antennas"][0]["azimuth_magnetic_deg"].is_null());
  ASSERT_FALSE(j["antennas"][0]["error"].is_null());
  EXPECT_THAT(j["antennas"][0]["error"].get<std::string>(), HasSubstr("walking a few metres round it"));
}

TEST_F(MeasureCli, PhotosOverANarrowArcAreWarnedOf) {
  const auto cap = copy("narrow-arc");
  // The ROI's photo and the next one: the antenna seen over about 7°.
  std::string shots = "index,t,image\n";
  const auto lines = io::read_text(capture() / "shots.csv");
  auto at = lines.rfind('\n', lines.find(roi_image_)) + 1;
  for (int i = 0; i < 2; ++i) {
    const auto end = lines.find('\n', at);
    shots += fmt::format("{},{}\n", i, lines.substr(lines.find(',', at) + 1, end - lines.find(',', at) - 1));
    at = end + 1;
  }
  test::write_file(cap / "shots.csv", shots);
  const auto json = *dir_ / "narrow-arc.json";
  const auto r =
      test::run_cli(measure(cap, fmt::format("--model {} --roi {} --json '{}'", model_, roi_, json.string())));
  const auto j = nlohmann::json::parse(io::read_text(json));
  const auto warnings = j["antennas"][0]["warnings"].dump();
  EXPECT_THAT(warnings, HasSubstr("the photos see the antenna over only 6."));
  EXPECT_THAT(warnings, HasSubstr("(less than 10°): its attitude rests on nearly one outline"));
  EXPECT_THAT(warnings, HasSubstr("photograph it over a wider arc")) << r.err;
}

TEST_F(MeasureCli, ModelInMillimetresAndOtherBadArgumentsAreNamed) {
  // The built-in panel written in millimetres.
  const auto panel = model::builtin_panel(model_);
  std::string obj;
  for (const auto& v : panel.mesh_antenna.vertices)
    obj += fmt::format("v {} {} {}\n", 1e3 * v.x(), 1e3 * v.y(), 1e3 * v.z());
  for (const auto& t : panel.mesh_antenna.triangles) obj += fmt::format("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1);
  const auto mesh = *dir_ / "panel-mm.obj";
  test::write_file(mesh, obj);
  auto r =
      test::run_cli(measure(capture(), fmt::format("--model '{}' --model-canonical --roi {}", mesh.string(), roi_)));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("--model-units mm"));

  r = test::run_cli(measure(capture(), fmt::format("--model {} --roi images/nope.jpg:1,2,30,40", model_)));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("'images/nope.jpg' is no photo of the capture"));

  r = test::run_cli(measure(capture(), fmt::format("--model {} --roi {}:900,700,100,100", model_, roi_image_)));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("reaches outside the 960×720 image"));

  r = test::run_cli(measure(capture(), fmt::format("--model no-such-panel --roi {}", roi_)));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("not a built-in panel"));

  r = test::run_cli(measure(capture(), fmt::format("--model {} --model {} --model {} --roi {} --roi {}", model_, model_,
                                                   model_, roi_, roi_)));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("3 models for 2 regions"));

  const auto bare = *dir_ / "bare.yaml";
  test::write_file(bare, "format: antpose-device\nversion: 1\ndevice: {id: bare}\n");
  r = test::run_cli(
      fmt::format("measure '{}' --device '{}' --model {} --roi {}", capture().string(), bare.string(), model_, roi_));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("no camera intrinsics"));
}

}  // namespace
}  // namespace antpose
