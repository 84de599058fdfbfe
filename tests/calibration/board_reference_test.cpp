#include "antpose/calibration/board_reference.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/test_support.hpp"

namespace antpose::calibration {
namespace {

using ::testing::HasSubstr;

std::string message_of(const std::string& content) {
  test::TempDir dir;
  test::write_file(dir / "board_reference.csv", content);
  try {
    read_board_reference(dir / "board_reference.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(BoardReference, ReadsTheThesisExample) {
  test::TempDir dir;
  test::write_file(dir / "board_reference.csv",
                   "placement,axis,ref,angle_deg\nhor_0_90,X,N,0\nhor_0_90,Y,N,90\nhor_0_90,Z,G,0\n\ndown_20,Z,G,20\n");
  const auto ref = read_board_reference(dir / "board_reference.csv");
  ASSERT_EQ(ref.lines.size(), 4u);
  EXPECT_EQ(ref.placements(), (std::vector<std::string>{"hor_0_90", "down_20"}));
  EXPECT_EQ(ref.lines[1].axis, BoardAxis::kY);
  EXPECT_EQ(ref.lines[1].ref, AngleReference::kNorth);
  EXPECT_NEAR(ref.lines[1].angle, std::numbers::pi / 2, 1e-15);
  EXPECT_EQ(ref.lines[3].line, 6u);  // the blank line still counts
  EXPECT_EQ(ref.lines_of("down_20").size(), 1u);
  EXPECT_EQ(ref.lines_of("hor_0_90").size(), 3u);
}

TEST(BoardReference, EveryBadValueNamesFileLineAndWhatWasExpected) {
  const std::string h = "placement,axis,ref,angle_deg\n";
  EXPECT_THAT(message_of(h + "a,Z,G,0\na,W,G,0\n"), HasSubstr("board_reference.csv:3: column 'axis': 'W' is not a board axis, expected X, Y or Z"));
  EXPECT_THAT(message_of(h + "a,Z,U,0\n"), HasSubstr("board_reference.csv:2: column 'ref': 'U' is not a reference, expected G"));
  EXPECT_THAT(message_of(h + "a,Z,G,181\n"), HasSubstr(":2: column 'angle_deg': 181 is outside [0, 180] (a G angle)"));
  EXPECT_THAT(message_of(h + "a,Z,G,-1\n"), HasSubstr("outside [0, 180]"));
  EXPECT_THAT(message_of(h + "a,X,N,360\n"), HasSubstr(":2: column 'angle_deg': 360 is outside [0, 360) (an N angle)"));
  EXPECT_THAT(message_of(h + "a,X,N,ten\n"), HasSubstr(":2: column 'angle_deg': 'ten' is not a number"));
  EXPECT_THAT(message_of(h + "a,X,N,10\nb,X,N,10\na,X,N,12\n"),
              HasSubstr(":4: placement 'a', axis X, ref N repeats line 2"));
  EXPECT_THAT(message_of(h + ",X,N,10\n"), HasSubstr(":2: column 'placement' is empty"));
  EXPECT_THAT(message_of("placement,axis,angle_deg\na,X,10\n"), HasSubstr("ref"));
  EXPECT_THAT(message_of(h), HasSubstr("no reference lines"));
  // The same axis with both references is two different measurements, not a duplicate.
  EXPECT_EQ(message_of(h + "a,Z,G,10\na,Z,N,10\n"), "no error");
}

TEST(BoardReference, ShotPlacementsAndPlacementsWithoutShots) {
  Capture c;
  c.shots_file = "cap/shots.csv";
  EXPECT_THROW(
      {
        try {
          shot_placements(c);
        } catch (const InputError& e) {
          EXPECT_THAT(e.what(), HasSubstr("cap/shots.csv: no 'placement' column"));
          throw;
        }
      },
      InputError);
  c.shot_extra_columns = {"exposure_note", "placement"};
  for (int i = 0; i < 3; ++i) {
    Shot s;
    s.index = i;
    s.image = "images/img_" + std::to_string(i) + ".jpg";
    s.extra = {"x", i < 2 ? "hor" : "vert"};
    s.source_line = static_cast<std::size_t>(i + 2);
    c.shots.push_back(s);
  }
  EXPECT_EQ(shot_placements(c), (std::vector<std::string>{"hor", "hor", "vert"}));
  c.shots[1].extra[1].clear();
  try {
    shot_placements(c);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("cap/shots.csv:3: shot 1 ('images/img_1.jpg'): column 'placement' is empty"));
  }

  test::TempDir dir;
  test::write_file(dir / "board_reference.csv", "placement,axis,ref,angle_deg\nhor,Z,G,0\ntilted,Z,G,20\n");
  const auto ref = read_board_reference(dir / "board_reference.csv");
  try {
    check_board_reference(ref, {"hor", "hor", "vert"});
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("board_reference.csv:3: placement 'tilted' has no shot (shots.csv names: hor, vert)"));
  }
  EXPECT_NO_THROW(check_board_reference(ref, {"hor", "tilted", "vert"}));
}

}  // namespace
}  // namespace antpose::calibration
