// Inputs of the camera calibration: the thesis's (OpenCV tutorial sample's) XML settings file,
// our YAML config, camera files, and photos that must be refused with a per-photo reason.
#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "antpose/camera/calibrate_camera.hpp"
#include "antpose/io/text_file.hpp"
#include "camera/camera_test_support.hpp"
#include "support/test_support.hpp"

namespace antpose::camera {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using test::shared_path;

const fs::path chess() { return shared_path("data/camera/opencv-chessboard-9x6"); }

// The settings file of OpenCV's camera_calibration tutorial sample (in_VID5.xml), which the
// thesis shows in fig. 7.9, with its element names and quoting.
std::string thesis_xml(const std::map<std::string, std::string>& replace = {}, const std::string& drop = "") {
  const std::vector<std::pair<std::string, std::string>> elements{
      {"BoardSize_Width", "9"},
      {"BoardSize_Height", "6"},
      {"Square_Size", "25"},
      {"Calibrate_Pattern", "\"CHESSBOARD\""},
      {"Input", "\"images/CameraCalibration/VID5/VID5.xml\""},
      {"Input_FlipAroundHorizontalAxis", "0"},
      {"Input_Delay", "100"},
      {"Calibrate_NrOfFrameToUse", "25"},
      {"Calibrate_FixAspectRatio", "1"},
      {"Calibrate_AssumeZeroTangentialDistortion", "1"},
      {"Calibrate_FixPrincipalPointAtTheCenter", "1"},
      {"Write_outputFileName", "\"out_camera_data.xml\""},
      {"Write_DetectedFeaturePoints", "1"},
      {"Write_extrinsicParameters", "1"},
      {"Show_UndistortedImage", "1"}};
  std::string s = "<?xml version=\"1.0\"?>\n<opencv_storage>\n<Settings>\n";
  for (const auto& [name, value] : elements) {
    if (name == drop) continue;
    const auto it = replace.find(name);
    s += fmt::format("  <{0}>{1}</{0}>\n", name, it == replace.end() ? value : it->second);
  }
  for (const auto& [name, value] : replace)
    if (std::none_of(elements.begin(), elements.end(), [&](const auto& e) { return e.first == name; }))
      s += fmt::format("  <{0}>{1}</{0}>\n", name, value);
  return s + "</Settings>\n</opencv_storage>\n";
}

TEST(CalibrationSettings, ThesisXmlSettingsFileIsAccepted) {
  test::TempDir dir;
  test::write_file(dir / "in_VID5.xml", thesis_xml());
  Diagnostics diagnostics;
  const auto s = read_calibration_settings(dir / "in_VID5.xml", diagnostics);
  ASSERT_TRUE(s.board);
  EXPECT_EQ(s.board->type, BoardType::kChessboard);
  EXPECT_EQ(s.board->cols, 9);
  EXPECT_EQ(s.board->rows, 6);
  EXPECT_DOUBLE_EQ(s.board->square_m, 0.025);
  EXPECT_TRUE(diagnostics.mentions("<Square_Size> 25 read as millimetres (= 0.025 m)"));
  EXPECT_TRUE(s.fix_aspect_ratio);
  EXPECT_EQ(s.aspect_ratio, 1.0);
  EXPECT_TRUE(s.zero_tangent);
  EXPECT_TRUE(s.fix_principal_point);
  EXPECT_FALSE(s.flip_vertical);
  EXPECT_EQ(s.max_images, 25);

  // Calibrating the chessboard set with it: fx = fy, p1 = p2 = 0, principal point at the centre.
  Diagnostics d2;
  const auto r = calibrate_camera(chess(), s, d2);
  EXPECT_TRUE(d2.empty());  // the board agrees with board.yaml
  EXPECT_EQ(r.intrinsics.fx, r.intrinsics.fy);
  EXPECT_EQ(r.intrinsics.distortion[2], 0.0);
  EXPECT_EQ(r.intrinsics.distortion[3], 0.0);
  EXPECT_EQ(r.intrinsics.cx, 319.5);
  EXPECT_EQ(r.intrinsics.cy, 239.5);
  EXPECT_NEAR(r.intrinsics.fx, 536.0, 5.0);
  EXPECT_THAT(r.flag_names, ::testing::UnorderedElementsAre("CALIB_FIX_ASPECT_RATIO", "CALIB_FIX_PRINCIPAL_POINT",
                                                            "CALIB_ZERO_TANGENT_DIST"));
}

TEST(CalibrationSettings, EveryBadXmlValueNamesFileElementAndExpectation) {
  test::TempDir dir;
  const fs::path file = dir / "settings.xml";
  struct Case {
    std::map<std::string, std::string> replace;
    std::string drop, message;
  };
  const std::vector<Case> cases{
      {{{"BoardSize_Width", "1"}}, "", "<BoardSize_Width> is 1, expected an integer from 2 to 1000"},
      {{{"BoardSize_Height", "\"six\""}}, "", "<BoardSize_Height> is 'six', expected an integer from 2 to 1000"},
      {{{"BoardSize_Height", "6.5"}}, "", "<BoardSize_Height> is 6.5, expected an integer"},
      {{}, "BoardSize_Width", "<BoardSize_Width> is missing, expected an integer from 2 to 1000"},
      {{{"Calibrate_Pattern", "\"CHECKERBOARD\""}}, "",
       "<Calibrate_Pattern> is 'CHECKERBOARD', expected \"CHESSBOARD\", \"CIRCLES_GRID\", \"ASYMMETRIC_CIRCLES_GRID\" or "
       "\"CHARUCOBOARD\""},
      {{{"Square_Size", "-2"}}, "", "<Square_Size> is -2, expected a positive square side"},
      {{}, "Square_Size", "<Square_Size> is missing"},
      {{{"Calibrate_FixAspectRatio", "20"}}, "",
       "<Calibrate_FixAspectRatio> is 20, expected 0 (fx, fy free) or the fixed ratio fx/fy between 0.1 and 10"},
      {{{"Input_FlipAroundHorizontalAxis", "2"}}, "", "<Input_FlipAroundHorizontalAxis> is 2, expected 0 or 1"},
      {{{"Calibrate_AssumeZeroTangentialDistortion", "\"yes\""}}, "",
       "<Calibrate_AssumeZeroTangentialDistortion> is 'yes', expected 0 or 1"},
      {{{"Calibrate_FixPrincipalPointAtTheCenter", "-1"}}, "",
       "<Calibrate_FixPrincipalPointAtTheCenter> is -1, expected 0 or 1"},
      {{{"Calibrate_NrOfFrameToUse", "0"}}, "", "<Calibrate_NrOfFrameToUse> is 0, expected an integer from 1"},
      {{{"Calibrate_UseFisheyeModel", "1"}}, "", "<Calibrate_UseFisheyeModel> is 1, but antpose models"},
      {{{"Input_Delay", "-5"}}, "", "<Input_Delay> is -5, expected an integer from 0"},
      {{{"Write_extrinsicParameters", "3"}}, "", "<Write_extrinsicParameters> is 3, expected 0 or 1"},
      {{{"Calibrate_Pattern", "\"CHARUCOBOARD\""}, {"Marker_Size", "30"}, {"ArUco_Dict_Name", "\"DICT_6X6_250\""}},
       "", "<Marker_Size> is 30, expected a marker side between 0 and <Square_Size> = 25"},
      {{{"Calibrate_Pattern", "\"CHARUCOBOARD\""}, {"Marker_Size", "12"}, {"ArUco_Dict_Name", "\"DICT_9X9_1\""}},
       "", "<ArUco_Dict_Name> is 'DICT_9X9_1', expected an OpenCV ArUco dictionary name"},
  };
  for (const auto& c : cases) {
    test::write_file(file, thesis_xml(c.replace, c.drop));
    Diagnostics diagnostics;
    try {
      read_calibration_settings(file, diagnostics);
      ADD_FAILURE() << "accepted: " << c.message;
    } catch (const InputError& e) {
      EXPECT_EQ(e.file(), file);
      EXPECT_THAT(e.what(), HasSubstr(file.string()));
      EXPECT_THAT(e.what(), HasSubstr(c.message));
    }
  }
  // Not a settings file / not FileStorage at all.
  test::write_file(file, "<?xml version=\"1.0\"?>\n<opencv_storage><Other>1</Other></opencv_storage>\n");
  Diagnostics diagnostics;
  EXPECT_THROW(
      {
        try {
          read_calibration_settings(file, diagnostics);
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), HasSubstr("no <Settings> element"));
          throw;
        }
      },
      InputError);
  test::write_file(file, "<?xml version=\"1.0\"?>\n<opencv_storage><Settings><BoardSize_Width>9</Settings>\n");
  EXPECT_THROW(read_calibration_settings(file, diagnostics), InputError);
  // A ChArUco pattern from the newer sample is accepted.
  test::write_file(file, thesis_xml({{"Calibrate_Pattern", "\"CHARUCOBOARD\""}, {"BoardSize_Width", "5"},
                                     {"BoardSize_Height", "7"}, {"Square_Size", "0.04"}, {"Marker_Size", "0.02"},
                                     {"ArUco_Dict_Name", "\"DICT_6X6_250\""}}));
  const auto s = read_calibration_settings(file, diagnostics);
  EXPECT_EQ(s.board->type, BoardType::kCharuco);
  EXPECT_EQ(s.board->marker_m, 0.02);
  EXPECT_EQ(s.board->dictionary, "DICT_6X6_250");
}

TEST(CalibrationSettings, SettingsBoardWinsOverBoardYamlWithAWarning) {
  test::TempDir dir;
  test::write_file(dir / "s.xml", thesis_xml({{"Square_Size", "0.03"}, {"Calibrate_FixAspectRatio", "0"},
                                              {"Calibrate_AssumeZeroTangentialDistortion", "0"},
                                              {"Calibrate_FixPrincipalPointAtTheCenter", "0"}}));
  Diagnostics diagnostics;
  const auto s = read_calibration_settings(dir / "s.xml", diagnostics);
  EXPECT_TRUE(diagnostics.empty());
  const auto r = calibrate_camera(chess(), s, diagnostics);
  EXPECT_TRUE(diagnostics.mentions("the settings' board (chessboard 9x6, square 0.03 m) differs from"));
  EXPECT_TRUE(diagnostics.mentions("(chessboard 9x6, square 0.025 m); using the settings' board"));
  EXPECT_EQ(diagnostics.warnings()[0].file, dir / "s.xml");
  // The square only scales the translations: intrinsics unchanged, distances × 1.2.
  const auto ref = test_data::reference("opencv-chessboard-9x6", "measured_default");
  EXPECT_EQ(r.board.square_m, 0.03);
  // (float object points round differently: 1e-4 px)
  EXPECT_NEAR(r.intrinsics.fx, ref.fx, 1e-3);
  EXPECT_NEAR(r.images[0].tvec.z(), 1.2 * ref.node["extrinsics"]["left01.jpg"]["tvec"][2].as<double>(), 1e-6);
}

TEST(CalibrationSettings, OwnYamlConfig) {
  test::TempDir dir;
  const fs::path file = dir / "camera-settings.yaml";
  test::write_file(file, R"(board: {type: chessboard, cols: 9, rows: 6, square_m: 0.025}
fix_aspect_ratio: 1.0
zero_tangent_distortion: false
fix_principal_point: false
distortion_coefficients: 4
flip_vertical: false
max_images: 10
detection:
  fast_check: true
  subpix_epsilon: 0.1
  min_laplacian_variance: 50
robust:
  outlier_factor: 4
  outlier_min_px: 1.5
  min_images: 5
)");
  Diagnostics diagnostics;
  const auto s = read_calibration_settings(file, diagnostics);
  EXPECT_TRUE(diagnostics.empty());
  EXPECT_EQ(s.board->cols, 9);
  EXPECT_TRUE(s.fix_aspect_ratio);
  EXPECT_EQ(s.distortion_coefficients, 4);
  EXPECT_EQ(s.max_images, 10);
  EXPECT_TRUE(s.detection.fast_check);
  EXPECT_EQ(s.detection.subpix_epsilon, 0.1);
  EXPECT_EQ(s.detection.min_laplacian_variance, 50.0);
  EXPECT_EQ(s.outlier_factor, 4.0);
  EXPECT_EQ(s.min_images, 5);
  const auto r = calibrate_camera(chess(), s, diagnostics);
  EXPECT_EQ(r.used_count(), 10u);
  EXPECT_EQ(r.intrinsics.distortion[4], 0.0);  // k3 fixed
  EXPECT_THAT(r.images[12].reason, HasSubstr("not used: the first 10 usable photos were enough"));

  const std::vector<std::pair<std::string, std::string>> bad{
      {"fix_aspect_ratio: 30\n", ":1: fix_aspect_ratio is 30, expected true/false or the ratio fx/fy (0.1 to 10)"},
      {"zero_tangent: true\n", ":1: unknown key 'zero_tangent', expected one of board, detection"},
      {"distortion_coefficients: 3\n", ":1: distortion_coefficients is 3, expected 5 (k1 k2 p1 p2 k3), 4 (k3 = 0)"},
      {"detection:\n  subpix_window: 0\n", ":2: detection.subpix_window is 0, expected an integer from 1 to 100"},
      {"detection:\n  fastcheck: true\n", ":2: unknown key 'detection.fastcheck'"},
      {"robust:\n  min_images: 2\n", ":2: robust.min_images is 2, expected at least 3"},
      {"flip_vertical: maybe\n", ":1: flip_vertical is 'maybe', expected true or false"},
      {"board: {type: chessboard, cols: 9, rows: 6, square_m: -1}\n", ":1: board: square_m is -1 m"},
      {"intrinsics_guess: nowhere.yaml\n", "nowhere.yaml: camera file not found"},
      {"? [a, b]\n: 1\n", ":1: a key is a list of 2, expected a name"},
  };
  for (const auto& [text, message] : bad) {
    test::write_file(file, text);
    try {
      read_calibration_settings(file, diagnostics);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const InputError& e) {
      EXPECT_THAT(e.what(), HasSubstr(message)) << text;
    }
  }
}

TEST(CameraFile, WrittenLikeTheTutorialSampleReadBackAndNeverOverwritten) {
  Diagnostics diagnostics;
  const auto r = calibrate_camera(chess(), CalibrationSettings{}, diagnostics);
  test::TempDir dir;
  const fs::path out = dir / "camera.yaml";
  write_camera_file(out, r, false);
  const std::string text = io::read_text(out);
  for (const char* key : {"calibration_time", "nr_of_frames: 13", "image_width: 640", "image_height: 480",
                          "board_width: 9", "board_height: 6", "square_size", "flags: 0", "camera_matrix: !!opencv-matrix",
                          "distortion_coefficients: !!opencv-matrix", "avg_reprojection_error",
                          "per_view_reprojection_errors", "extrinsic_parameters", "camera_matrix_std_dev"})
    EXPECT_THAT(text, HasSubstr(key));
  const CameraFile c = read_camera_file(out);
  EXPECT_EQ(c.intrinsics.fx, r.intrinsics.fx);
  EXPECT_EQ(c.intrinsics.cy, r.intrinsics.cy);
  EXPECT_EQ(c.intrinsics.distortion, r.intrinsics.distortion);
  EXPECT_EQ(c.intrinsics.width, 640);
  EXPECT_EQ(*c.rms_px, r.rms_px);
  const auto p = profile_camera(r);
  EXPECT_EQ(p.intrinsics.fx, r.intrinsics.fx);
  EXPECT_EQ(p.rms_px, r.rms_px);
  // No overwrite without force; the old file stays.
  try {
    write_camera_file(out, r, false);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("exists already; pass --force"));
  }
  write_camera_file(out, r, true);
  // OpenCV's published file of these images reads too (5×1 distortion, no calibration_time).
  const CameraFile pub = read_camera_file(chess() / "published/left_intrinsics.yml");
  EXPECT_DOUBLE_EQ(pub.intrinsics.fx, 535.91573396163199);
  EXPECT_DOUBLE_EQ(pub.intrinsics.distortion[4], 0.23839153080878486);
  // Bad camera files.
  test::write_file(dir / "bad.yaml", "%YAML:1.0\n---\nimage_width: 640\nimage_height: 480\n");
  EXPECT_THROW(
      {
        try {
          read_camera_file(dir / "bad.yaml");
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), HasSubstr("camera_matrix is missing, expected a 3x3 !!opencv-matrix"));
          throw;
        }
      },
      InputError);
  test::write_file(dir / "bad2.yaml", "%YAML:1.0\n---\nimage_width: -640\n");
  EXPECT_THROW(
      {
        try {
          read_camera_file(dir / "bad2.yaml");
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), HasSubstr("image_width is -640, expected a positive number of pixels"));
          throw;
        }
      },
      InputError);
}

// A capture with the 13 good photos plus one without a board, a blurred one, one with the
// board partly out of view and an unreadable file: each gets its reason, the rest calibrates.
fs::path capture_with_bad_photos(const test::TempDir& dir, std::size_t good) {
  const fs::path root = dir / "cap";
  fs::create_directories(root / "images");
  fs::copy_file(chess() / "capture.yaml", root / "capture.yaml");
  fs::copy_file(chess() / "board.yaml", root / "board.yaml");
  std::string shots = "index,t,image\n";
  std::size_t k = 0;
  for (const auto& entry : test_data::read_corner_views(chess() / "corners.csv")) {
    if (k >= good) break;
    fs::copy_file(chess() / "images" / entry.name, root / "images" / entry.name);
    shots += fmt::format("{},{},images/{}\n", k, k, entry.name);
    ++k;
  }
  const cv::Mat left01 = cv::imread((chess() / "images/left01.jpg").string(), cv::IMREAD_GRAYSCALE);
  cv::Mat page(480, 640, CV_8UC1, cv::Scalar(235));
  cv::putText(page, "no board in this photo", {40, 240}, cv::FONT_HERSHEY_SIMPLEX, 1.5, 20, 3);
  cv::imwrite((root / "images/page.png").string(), page);
  cv::Mat blurred;
  cv::GaussianBlur(left01, blurred, cv::Size(), 2.0);
  cv::imwrite((root / "images/blurred.png").string(), blurred);
  cv::Mat partial(480, 640, CV_8UC1, cv::Scalar(128));
  left01(cv::Rect(300, 0, 340, 480)).copyTo(partial(cv::Rect(0, 0, 340, 480)));
  cv::imwrite((root / "images/partial.png").string(), partial);
  test::write_file(root / "images/broken.jpg", "this is not a JPEG file");
  for (const char* name : {"page.png", "blurred.png", "partial.png", "broken.jpg"}) {
    shots += fmt::format("{},{},images/{}\n", k, k, name);
    ++k;
  }
  test::write_file(root / "shots.csv", shots);
  return root;
}

TEST(CalibrateCamera, BadPhotosAreReportedAndTheCalibrationContinues) {
  test::TempDir dir;
  const fs::path root = capture_with_bad_photos(dir, 13);
  Diagnostics diagnostics;
  std::size_t calls = 0;
  const auto r = calibrate_camera(root, CalibrationSettings{}, diagnostics,
                                  [&](const CalibrationImage&, std::size_t done, std::size_t total) {
                                    ++calls;
                                    EXPECT_EQ(done, calls);
                                    EXPECT_EQ(total, 17u);
                                  });
  EXPECT_EQ(calls, 17u);
  EXPECT_EQ(r.used_count(), 13u);
  const auto rejected = r.rejected();
  ASSERT_EQ(rejected.size(), 4u);
  EXPECT_EQ(rejected[0].first, "images/page.png");
  EXPECT_THAT(rejected[0].second, HasSubstr("no board found"));
  EXPECT_EQ(rejected[1].first, "images/blurred.png");
  EXPECT_THAT(rejected[1].second, HasSubstr("blurred (variance of Laplacian"));
  EXPECT_EQ(rejected[2].first, "images/partial.png");
  EXPECT_THAT(rejected[2].second, HasSubstr("board partly out of view"));
  EXPECT_EQ(rejected[3].first, "images/broken.jpg");
  EXPECT_THAT(rejected[3].second, HasSubstr("cannot be decoded: not a JPEG, PNG or TIFF photo"));
  for (const char* name : {"page.png", "blurred.png", "partial.png", "broken.jpg"}) {
    const bool named = std::any_of(diagnostics.warnings().begin(), diagnostics.warnings().end(),
                                   [&](const Warning& w) { return w.file.filename() == name; });
    EXPECT_TRUE(named) << name;
  }
  // The 13 good photos give the reference calibration.
  const auto ref = test_data::reference("opencv-chessboard-9x6", "measured_default");
  EXPECT_NEAR(r.intrinsics.fx, ref.fx, 1e-6);
  EXPECT_NEAR(r.rms_px, ref.rms, 1e-6);
  const std::string table = describe(r);
  EXPECT_THAT(table, HasSubstr("images/broken.jpg"));
  EXPECT_THAT(table, HasSubstr("refused: cannot be decoded"));
  EXPECT_THAT(table, HasSubstr("13 of 17 photos used"));
  fmt::print("{}", table);
  // The camera file lists the refused photos with their reasons and stays readable.
  write_camera_file(dir / "camera.yaml", r, false);
  const std::string text = io::read_text(dir / "camera.yaml");
  EXPECT_THAT(text, HasSubstr("images/broken.jpg"));
  EXPECT_EQ(read_camera_file(dir / "camera.yaml").intrinsics.fx, r.intrinsics.fx);
  cv::FileStorage fs((dir / "camera.yaml").string(), cv::FileStorage::READ);
  const cv::FileNode rejected_node = fs["rejected_images"];
  ASSERT_EQ(rejected_node.size(), 4u);
  EXPECT_EQ(static_cast<std::string>(rejected_node[2]["reason"]), rejected[2].second);
}

TEST(CalibrateCamera, OnePhotoClaimingAnotherSizeIsRefusedAloneEvenWhenFirst) {
  test::TempDir dir;
  const fs::path root = capture_with_bad_photos(dir, 13);
  // The first photo listed claims 1280×960 px in its header (the photos' aspect ratio): the size
  // most photos share decides, not the first.
  test::write_file(root / "images/claim.jpg", test::jpeg_claiming(1280, 960));
  test::write_file(root / "shots.csv",
                   "index,t,image\n99,0,images/claim.jpg\n" +
                       io::read_text(root / "shots.csv").substr(std::string("index,t,image\n").size()));
  Diagnostics diagnostics;
  const auto r = calibrate_camera(root, CalibrationSettings{}, diagnostics);
  EXPECT_EQ(r.used_count(), 13u);
  const auto rejected = r.rejected();
  ASSERT_EQ(rejected.size(), 5u);
  EXPECT_EQ(rejected[0].first, "images/claim.jpg");
  EXPECT_EQ(rejected[0].second, "image is 1280x960 px, most photos are 640x480 px (one camera mode per calibration)");
  EXPECT_NEAR(r.intrinsics.fx, test_data::reference("opencv-chessboard-9x6", "measured_default").fx, 1e-6);
}

TEST(CalibrateCamera, TooFewGoodPhotosIsAMeasurementError) {
  test::TempDir dir;
  const fs::path root = capture_with_bad_photos(dir, 2);
  Diagnostics diagnostics;
  try {
    calibrate_camera(root, CalibrationSettings{}, diagnostics);
    FAIL();
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("camera calibration: 2 usable photos (need at least 3); refused:"));
    EXPECT_THAT(e.what(), HasSubstr("images/broken.jpg: cannot be decoded"));
    EXPECT_THAT(e.what(), HasSubstr("images/blurred.png: blurred"));
  }
}

TEST(CalibrateCamera, FlipAndIntrinsicsGuess) {
  Diagnostics diagnostics;
  const auto plain = calibrate_camera(chess(), CalibrationSettings{}, diagnostics);
  CalibrationSettings flip;
  flip.flip_vertical = true;
  const auto flipped = calibrate_camera(chess(), flip, diagnostics);
  // Upside-down photos: the principal point mirrors about the image's middle row.
  EXPECT_NEAR(flipped.intrinsics.cy, 479.0 - plain.intrinsics.cy, 0.3);
  EXPECT_NEAR(flipped.intrinsics.fx, plain.intrinsics.fx, 0.3);
  EXPECT_NEAR(flipped.intrinsics.distortion[2], -plain.intrinsics.distortion[2], 2e-4);  // p1 changes sign
  // A guess with a fixed principal point keeps it.
  CalibrationSettings guess;
  guess.intrinsics_guess = plain.intrinsics;
  guess.intrinsics_guess->cx = 330.0;
  guess.fix_principal_point = true;
  const auto g = calibrate_camera(chess(), guess, diagnostics);
  EXPECT_EQ(g.intrinsics.cx, 330.0);
  EXPECT_THAT(g.flag_names, ::testing::Contains("CALIB_USE_INTRINSIC_GUESS"));
  EXPECT_GT(g.rms_px, plain.rms_px);
}

}  // namespace
}  // namespace antpose::camera
