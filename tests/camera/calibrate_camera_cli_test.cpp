// antpose calibrate camera: end to end on the chessboard set, and its input errors.
#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "antpose/camera/calibrate_camera.hpp"
#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose::camera {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using test::shared_path;

TEST(CalibrateCameraCli, WritesCameraYamlJsonAndPrintsTheTable) {
  test::TempDir dir;
  const fs::path chess = shared_path("data/camera/opencv-chessboard-9x6");
  const fs::path out = dir / "camera.yaml", json = dir / "camera.json";
  const auto r = test::run_cli(fmt::format("calibrate camera {} -o {} --json {}", chess.string(), out.string(),
                                           json.string()));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_THAT(r.out, HasSubstr("camera calibration of"));
  EXPECT_THAT(r.out, HasSubstr("images/left02.jpg                54  1.2198"));
  EXPECT_THAT(r.out, HasSubstr("13 of 13 photos used"));
  EXPECT_THAT(r.out, HasSubstr("fx = 536.0734 ± 1.3580 px"));
  EXPECT_THAT(r.out, HasSubstr("RMS reprojection error 0.4087 px"));
  EXPECT_THAT(r.err, ::testing::Not(HasSubstr("13/13")));  // no progress where stderr is no terminal
  const CameraFile c = read_camera_file(out);
  EXPECT_NEAR(c.intrinsics.fx, 536.0734168, 1e-4);
  // Progress for a wrapper: one JSON object per photo.
  const auto progress = test::run_cli(
      fmt::format("calibrate camera {} -o {} --force --progress json", chess.string(), (dir / "again.yaml").string()));
  ASSERT_EQ(progress.status, 0) << progress.err;
  EXPECT_THAT(progress.err, HasSubstr(R"("done":13,)"));
  EXPECT_THAT(progress.err, HasSubstr(R"("stage":"board detection","total":13})"));
  const auto j = nlohmann::json::parse(io::read_text(json));
  EXPECT_NEAR(j["cy_px"].get<double>(), 235.5368585, 1e-4);
  EXPECT_EQ(j["images"].size(), 13u);

  // Existing output: refused without --force (exit 2, before the run), replaced with it.
  const auto again = test::run_cli(fmt::format("calibrate camera {} -o {} --fix-aspect-ratio", chess.string(),
                                               out.string()));
  EXPECT_EQ(again.status, 2);
  EXPECT_THAT(again.err, HasSubstr("exists already; pass --force to replace it"));
  const auto forced = test::run_cli(fmt::format("calibrate camera {} -o {} --fix-aspect-ratio --zero-tangent "
                                                "--fix-principal-point --force",
                                                chess.string(), out.string()));
  ASSERT_EQ(forced.status, 0) << forced.err;
  EXPECT_THAT(forced.out, HasSubstr("CALIB_FIX_ASPECT_RATIO + CALIB_FIX_PRINCIPAL_POINT + CALIB_ZERO_TANGENT_DIST"));
  const CameraFile c2 = read_camera_file(out);
  EXPECT_EQ(c2.intrinsics.fx, c2.intrinsics.fy);
  EXPECT_EQ(c2.intrinsics.cx, 319.5);

  // Reuse: the first result as the guess.
  const auto guess = test::run_cli(fmt::format("calibrate camera {} -o {} --intrinsics-guess {}", chess.string(),
                                               (dir / "c3.yaml").string(), out.string()));
  ASSERT_EQ(guess.status, 0) << guess.err;
  EXPECT_THAT(guess.out, HasSubstr("CALIB_USE_INTRINSIC_GUESS"));
}

TEST(CalibrateCameraCli, InputAndMeasurementErrors) {
  test::TempDir dir;
  const fs::path chess = shared_path("data/camera/opencv-chessboard-9x6");
  test::write_file(dir / "bad.xml",
                   "<?xml version=\"1.0\"?>\n<opencv_storage><Settings><BoardSize_Width>0</BoardSize_Width>"
                   "</Settings></opencv_storage>\n");
  auto r = test::run_cli(fmt::format("calibrate camera {} --config {} -o {}", chess.string(),
                                     (dir / "bad.xml").string(), (dir / "o.yaml").string()));
  EXPECT_EQ(r.status, 2);
  EXPECT_THAT(r.err, HasSubstr("bad.xml: <BoardSize_Width> is 0, expected an integer from 2 to 1000"));
  EXPECT_FALSE(fs::exists(dir / "o.yaml"));
  // Too few photos: exit 3 with the reason; no output written.
  test::write_file(dir / "few.yaml", "max_images: 2\n");
  r = test::run_cli(fmt::format("calibrate camera {} --config {} -o {}", chess.string(), (dir / "few.yaml").string(),
                                (dir / "o.yaml").string()));
  EXPECT_EQ(r.status, 3);
  EXPECT_THAT(r.err, HasSubstr("2 usable photos (need at least 3)"));
  EXPECT_FALSE(fs::exists(dir / "o.yaml"));
}

}  // namespace
}  // namespace antpose::camera
