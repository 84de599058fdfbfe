#include "antpose/model/box_file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "support/test_support.hpp"

namespace antpose::model {
namespace {
using ::testing::HasSubstr;

Iso3 known_box_pose() {
  Iso3 T_mesh_antenna = Iso3::Identity();
  T_mesh_antenna.linear() = exp_so3(Vec3(0.3, -1.2, 2.0));
  T_mesh_antenna.translation() = Vec3(1.5, -2.0, 0.7);
  return T_mesh_antenna;
}

const Vec3 kSize(0.30, 0.16, 1.31);

// Box file text for corners in A..H order, with a custom order of lines.
std::string box_text(const std::array<Vec3, 8>& c, const std::array<int, 8>& order = {0, 1, 2, 3, 4, 5, 6, 7}) {
  std::string out;
  for (int k : order) out += fmt::format("{} {} {} {}\n", "ABCDEFGH"[k], c[k].x(), c[k].y(), c[k].z());
  return out;
}

TEST(BoxFile, RecoversKnownPoseAndSize) {
  const auto corners = box_corners(kSize, known_box_pose());
  // Any order, comments and blank lines.
  const std::string text = "# fitted by hand\n\n" + box_text(corners, {7, 2, 0, 5, 1, 6, 3, 4}) + "   # end\n";
  const AntennaBox box = parse_box_file(text, "box.txt");
  const Iso3 expected = known_box_pose().inverse();
  EXPECT_LT((box.T_antenna_mesh.linear() - expected.linear()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((box.T_antenna_mesh.translation() - expected.translation()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((box.size_m - kSize).cwiseAbs().maxCoeff(), 1e-9);
  // The corners land where the note puts them: A back-left-top, D in front of A, E below A.
  const auto in_antenna = box_corners(kSize);
  for (int k = 0; k < 8; ++k) EXPECT_LT((box.T_antenna_mesh * corners[k] - in_antenna[k]).norm(), 1e-9) << k;
  EXPECT_EQ(in_antenna[0], Vec3(-0.15, -0.08, 0.655));
  EXPECT_EQ(in_antenna[3], Vec3(-0.15, 0.08, 0.655));
  EXPECT_EQ(in_antenna[4], Vec3(-0.15, -0.08, -0.655));
}

TEST(BoxFile, ReadsMillimetresAndTheWrittenFormat) {
  std::array<Vec3, 8> corners = box_corners(kSize, known_box_pose());
  for (auto& c : corners) c *= 1000;
  test::TempDir dir;
  test::write_file(dir / "box.txt", format_box_file(corners));
  const AntennaBox box = read_box_file(dir / "box.txt", Units::kMillimetres);
  EXPECT_LT((box.T_antenna_mesh.translation() - known_box_pose().inverse().translation()).norm(), 1e-9);
  EXPECT_LT((box.size_m - kSize).norm(), 1e-9);
}

TEST(BoxFile, ToleratesHandPickedCorners) {
  auto corners = box_corners(kSize, known_box_pose());
  corners[2] += Vec3(0.002, -0.001, 0.0015);  // a few millimetres off
  corners[5] += Vec3(-0.001, 0.002, 0.0);
  const AntennaBox box = parse_box_file(box_text(corners), "box.txt");
  EXPECT_LT(rad2deg(rotation_distance(box.T_antenna_mesh.linear(), known_box_pose().inverse().linear())), 0.5);
  EXPECT_NEAR(box.T_antenna_mesh.linear().determinant(), 1.0, 1e-12);
}

TEST(BoxFile, MissingDuplicateAndUnknownLabels) {
  const auto c = box_corners(kSize);
  EXPECT_THAT(test::input_error([&] {
                parse_box_file(box_text(c, {0, 1, 2, 3, 4, 5, 7, 7}), "box.txt");
              }),
              HasSubstr("box.txt:8: corner H given twice (first on line 7)"));
  std::string text = box_text(c);
  text = text.substr(0, text.find("G "));  // drop G and H
  EXPECT_THAT(test::input_error([&] { parse_box_file(text, "box.txt"); }),
              HasSubstr("box.txt: missing corners G, H: a box file needs each of A B C D E F G H exactly once"));
  EXPECT_THAT(test::input_error([&] { parse_box_file("I 0 0 0\n", "box.txt"); }),
              HasSubstr("box.txt:1: unknown corner label 'I'"));
}

TEST(BoxFile, BadLinesNameFileAndLine) {
  EXPECT_THAT(test::input_error([] { parse_box_file("# c\nA 0 0 0\nB 1 x1 0\n", "box.txt"); }),
              HasSubstr("box.txt:3: bad number 'x1' for corner B"));
  EXPECT_THAT(test::input_error([] { parse_box_file("A 0 0\n", "box.txt"); }),
              HasSubstr("box.txt:1: 3 fields, expected 'LABEL x y z'"));
  EXPECT_THAT(test::input_error([] { parse_box_file("A 0 0 0 4\n", "box.txt"); }), HasSubstr("box.txt:1: 5 fields"));
}

TEST(BoxFile, CornersThatAreNotABox) {
  auto c = box_corners(kSize, known_box_pose());
  auto moved = c;
  moved[2] += known_box_pose().linear() * Vec3(0.05, 0, 0);  // C 5 cm off to the right
  const std::string message = test::input_error([&] { parse_box_file(box_text(moved), "box.txt"); });
  EXPECT_THAT(message, HasSubstr("box.txt: not a box: edges AD and BC should be parallel"));
  EXPECT_THAT(message, HasSubstr("check corners B and C (lines 2 and 3)"));

  auto same = c;
  same[1] = same[0];
  EXPECT_THAT(test::input_error([&] { parse_box_file(box_text(same), "box.txt"); }),
              HasSubstr("edge AB is 0 m long: corners A and B (lines 1 and 2) (nearly) coincide"));

  auto swapped = c;
  std::swap(swapped[2], swapped[3]);  // C and D
  EXPECT_THAT(test::input_error([&] { parse_box_file(box_text(swapped), "box.txt"); }),
              HasSubstr("edge DC runs opposite to AB (both should point along x_a (width)): either A and B (lines 1 "
                        "and 2) or D and C (lines 4 and 3) seem swapped"));
}

TEST(BoxFile, UnequalOppositeEdgesStateTheLengths) {
  // A thin, deep box: widening the front right edge by 3 mm tilts BC and FG by only 0.17°, so
  // the length check is what catches it.
  auto c = box_corners(Vec3(0.1, 1.0, 1.0));
  c[2].x() += 0.003;
  c[6].x() += 0.003;
  EXPECT_THAT(test::input_error([&] { parse_box_file(box_text(c), "box.txt"); }),
              HasSubstr("not a box: the four edges along x_a (width) should be equal but are AB = 0.1 m, DC = 0.103 m, "
                        "EF = 0.1 m, HG = 0.103 m (2.9 % apart, tolerance 2 %)"));
  c[6].x() -= 0.003;  // only C off now: DC is the one edge that disagrees
  EXPECT_THAT(test::input_error([&] { parse_box_file(box_text(c), "box.txt"); }),
              HasSubstr("(2.9 % apart, tolerance 2 %); DC (lines 4 and 3) is the odd one out"));
}

TEST(BoxFile, SkewedBoxIsNotRectangular) {
  auto c = box_corners(kSize);
  for (auto& p : c) p.x() += std::tan(deg2rad(5)) * p.y();  // shear: AD leans by 5°
  EXPECT_THAT(test::input_error([&] { parse_box_file(box_text(c), "box.txt"); }),
              HasSubstr("not a box: edges AB and AD should be perpendicular but meet at 85.00° (tolerance 2°); check "
                        "corners A, B and D (lines 1, 2, 4)"));
}

TEST(BoxFile, MirroredBoxSaysWhichLabelsSeemSwapped) {
  const auto c = box_corners(kSize, known_box_pose());
  // Left and right exchanged: A↔B, C↔D, E↔F, G↔H.
  const std::array<Vec3, 8> lr = {c[1], c[0], c[3], c[2], c[5], c[4], c[7], c[6]};
  const std::string message = test::input_error([&] { parse_box_file(box_text(lr), "box.txt"); });
  EXPECT_THAT(message, HasSubstr("box.txt: the corners form a mirrored box"));
  EXPECT_THAT(message, HasSubstr("left and right are swapped (A↔B, D↔C, E↔F, H↔G)"));
  // Width and depth exchanged: B↔D, F↔H.
  const std::array<Vec3, 8> wd = {c[0], c[3], c[2], c[1], c[4], c[7], c[6], c[5]};
  EXPECT_THAT(test::input_error([&] { parse_box_file(box_text(wd), "box.txt"); }),
              HasSubstr("B and D (and F and H) seem swapped"));
}

}  // namespace
}  // namespace antpose::model
