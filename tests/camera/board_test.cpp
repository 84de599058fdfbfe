// camera/board: a board description is checked before any photo is searched for it.
#include "antpose/camera/board.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "support/test_support.hpp"

namespace antpose::camera {
namespace {

using ::testing::HasSubstr;

std::string charuco(int cols, int rows, const char* dictionary) {
  return fmt::format("type: charuco\ncols: {}\nrows: {}\nsquare_m: 0.04\nmarker_m: 0.03\ndictionary: {}\n", cols, rows,
                     dictionary);
}

TEST(Board, AChArUcoBoardHasNoMoreMarkersThanItsDictionary) {
  const BoardSpec b = parse_board(charuco(10, 10, "DICT_4X4_50"), "board.yaml");  // 50 markers, 50 in the dictionary
  EXPECT_EQ(b.cols, 10);
  // Such a board cannot exist, and searching photos for it would take minutes each.
  EXPECT_THAT(test::input_error([] { parse_board(charuco(1000, 1000, "DICT_4X4_50"), "board.yaml"); }),
              HasSubstr("board.yaml:6: a 1000×1000 ChArUco board has 500000 markers but the dictionary DICT_4X4_50 "
                        "holds 50"));
  EXPECT_THAT(test::input_error([] { parse_board(charuco(11, 10, "DICT_4X4_50"), "board.yaml"); }),
              HasSubstr("has 55 markers"));
  EXPECT_NO_THROW(parse_board(charuco(11, 10, "DICT_4X4_100"), "board.yaml"));
}

}  // namespace
}  // namespace antpose::camera
