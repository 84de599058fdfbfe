// io::read_photo: a bad photo is a reason, never an exception or a crash.
#include "antpose/io/photo_file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A valid 64×48 JPEG whose frame header (SOF0) claims `width`×`height`.
std::string jpeg_claiming(int width, int height) {
  std::vector<uchar> bytes;
  cv::imencode(".jpg", cv::Mat(48, 64, CV_8UC1, cv::Scalar(100)), bytes);
  for (std::size_t i = 0; i + 8 < bytes.size(); ++i)
    if (bytes[i] == 0xFF && bytes[i + 1] == 0xC0) {  // length(2) precision(1) height(2) width(2)
      bytes[i + 5] = static_cast<uchar>(height >> 8), bytes[i + 6] = static_cast<uchar>(height & 0xFF);
      bytes[i + 7] = static_cast<uchar>(width >> 8), bytes[i + 8] = static_cast<uchar>(width & 0xFF);
      break;
    }
  return std::string(bytes.begin(), bytes.end());
}

TEST(PhotoFile, APhotoDecodesAndABadOneGivesItsReason) {
  test::TempDir dir;
  test::write_file(dir / "good.jpg", jpeg_claiming(64, 48));
  const Photo good = read_photo(dir / "good.jpg", cv::IMREAD_GRAYSCALE);
  ASSERT_TRUE(good.ok()) << good.problem;
  EXPECT_EQ(good.image.cols, 64);

  // 65000×65000 px is past OpenCV's limit of 2^30 pixels: its assertion becomes the reason.
  test::write_file(dir / "huge.jpg", jpeg_claiming(65000, 65000));
  const Photo huge = read_photo(dir / "huge.jpg", cv::IMREAD_GRAYSCALE);
  EXPECT_FALSE(huge.ok());
  EXPECT_TRUE(huge.image.empty());
  EXPECT_THAT(huge.problem, HasSubstr("cannot be decoded ("));

  test::write_file(dir / "text.jpg", "not a photo");
  EXPECT_THAT(read_photo(dir / "text.jpg", cv::IMREAD_GRAYSCALE).problem,
              HasSubstr("cannot be decoded: not a JPEG, PNG or TIFF photo, or truncated"));
  fs::create_directories(dir / "folder.jpg");
  EXPECT_EQ(read_photo(dir / "folder.jpg", cv::IMREAD_GRAYSCALE).problem, "is a folder, expected a file");
  EXPECT_EQ(read_photo(dir / "none.jpg", cv::IMREAD_GRAYSCALE).problem, "file not found");
}

}  // namespace
}  // namespace antpose::io
