// EXIF orientation: a rectangle of the upright photo covers the same pixels as its stored rectangle.
#include "antpose/io/exif_orientation.hpp"

#include <algorithm>
#include <vector>

#include <gtest/gtest.h>

namespace antpose::io {
namespace {

std::vector<int> values(const cv::Mat& image) {
  std::vector<int> v(image.begin<int>(), image.end<int>());
  std::sort(v.begin(), v.end());
  return v;
}

TEST(ExifOrientation, AnUprightRectangleAndItsStoredOneHoldTheSamePixels) {
  const cv::Size stored_size(7, 5);
  cv::Mat stored(stored_size, CV_32S);
  for (int y = 0; y < stored.rows; ++y)
    for (int x = 0; x < stored.cols; ++x) stored.at<int>(y, x) = 100 * y + x;  // every pixel its own value
  for (int orientation = 1; orientation <= 8; ++orientation) {
    const cv::Mat upright = upright_image(stored, orientation);
    ASSERT_EQ(upright.size(), upright_size(stored_size, orientation)) << orientation;
    const cv::Rect in_upright(1, 2, 3, 2);
    const cv::Rect in_stored = stored_rect(in_upright, stored_size, orientation);
    ASSERT_EQ((in_stored & cv::Rect({}, stored_size)), in_stored) << orientation;
    EXPECT_EQ(values(upright(in_upright)), values(stored(in_stored))) << orientation;
    // The whole upright photo is the whole stored one.
    EXPECT_EQ(stored_rect(cv::Rect({}, upright.size()), stored_size, orientation), cv::Rect({}, stored_size));
  }
  EXPECT_EQ(upright_size(stored_size, 6), cv::Size(5, 7));
  EXPECT_EQ(upright_image(stored, 6).at<int>(0, 0), 400);  // turned clockwise: the bottom-left comes first
  EXPECT_THROW(upright_size(stored_size, 9), std::invalid_argument);
}

}  // namespace
}  // namespace antpose::io
