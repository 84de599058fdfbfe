// io::read_photo: a bad photo is a reason, never an exception or a crash.
#include "antpose/io/photo_file.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <exiv2/exiv2.hpp>
#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "antpose/io/text_file.hpp"
#include "support/test_support.hpp"

namespace antpose::io {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using test::jpeg_claiming;

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
  EXPECT_EQ(read_photo(dir / "text.jpg", cv::IMREAD_GRAYSCALE).problem,
            "cannot be decoded: not a JPEG, PNG or TIFF photo");
  const std::string good_jpeg = jpeg_claiming(64, 48);
  test::write_file(dir / "cut.jpg", good_jpeg.substr(0, 20));
  EXPECT_EQ(read_photo(dir / "cut.jpg", cv::IMREAD_GRAYSCALE).problem,
            "cannot be decoded: not a JPEG, PNG or TIFF photo, or truncated");
  fs::create_directories(dir / "folder.jpg");
  EXPECT_EQ(read_photo(dir / "folder.jpg", cv::IMREAD_GRAYSCALE).problem, "is a folder, expected a file");
  EXPECT_EQ(read_photo(dir / "none.jpg", cv::IMREAD_GRAYSCALE).problem, "file not found");
}

TEST(PhotoFile, AHeaderGivesTheSizeItClaimsWithoutDecoding) {
  test::TempDir dir;
  test::write_file(dir / "good.jpg", jpeg_claiming(64, 48));
  const PhotoHeader good = read_photo_header(dir / "good.jpg");
  ASSERT_TRUE(good.ok()) << good.problem;
  EXPECT_EQ(good.width_px, 64);
  EXPECT_EQ(good.height_px, 48);
  // The claim, not the truth: decoding would need 900 MB.
  const PhotoHeader claim = read_photo_header(dir / "claim.jpg");
  EXPECT_EQ(claim.problem, "file not found");
  test::write_file(dir / "claim.jpg", jpeg_claiming(30000, 30000));
  const PhotoHeader huge = read_photo_header(dir / "claim.jpg");
  ASSERT_TRUE(huge.ok()) << huge.problem;
  EXPECT_EQ(huge.width_px, 30000);
  std::vector<uchar> png;
  cv::imencode(".png", cv::Mat(7, 5, CV_8UC3, cv::Scalar(1, 2, 3)), png);
  test::write_file(dir / "small.png", std::string(png.begin(), png.end()));
  const PhotoHeader small = read_photo_header(dir / "small.png");
  EXPECT_EQ(small.width_px, 5);
  EXPECT_EQ(small.height_px, 7);

  test::write_file(dir / "text.jpg", "not a photo");
  EXPECT_EQ(read_photo_header(dir / "text.jpg").problem, "not a JPEG, PNG or TIFF photo");
  test::write_file(dir / "cut.jpg", "\xFF\xD8\xFF\xE0 and no more");
  EXPECT_THAT(read_photo_header(dir / "cut.jpg").problem, HasSubstr("its header cannot be read ("));
  test::write_file(dir / "empty.jpg", "");
  EXPECT_EQ(read_photo_header(dir / "empty.jpg").problem, "not a JPEG, PNG or TIFF photo");
  // Another format's signature further in (DICOM's "DICM" at byte 128) is not decoded as such.
  test::write_file(dir / "dicom.jpg", std::string(128, '\0') + "DICM" + std::string(64, '\x92'));
  EXPECT_EQ(read_photo_header(dir / "dicom.jpg").problem, "not a JPEG, PNG or TIFF photo");
  EXPECT_EQ(read_photo(dir / "dicom.jpg", cv::IMREAD_GRAYSCALE).problem,
            "cannot be decoded: not a JPEG, PNG or TIFF photo");
  fs::create_directories(dir / "folder.jpg");
  EXPECT_EQ(read_photo_header(dir / "folder.jpg").problem, "is a folder, expected a file");
}

TEST(PhotoFile, PhotosAreReadAsStoredWhateverTheirExifOrientation) {
  test::TempDir dir;
  for (const int orientation : {1, 3, 6, 8}) {
    const auto file = dir / fmt::format("o{}.jpg", orientation);
    cv::imwrite(file.string(), cv::Mat(48, 64, CV_8UC1, cv::Scalar(90)));
    auto image = Exiv2::ImageFactory::open(file.string());
    image->readMetadata();
    image->exifData()["Exif.Image.Orientation"] = static_cast<std::uint16_t>(orientation);
    image->writeMetadata();
    const PhotoHeader header = read_photo_header(file);
    EXPECT_EQ(header.exif_orientation, orientation);
    EXPECT_EQ(header.width_px, 64);
    for (const int flags : {cv::IMREAD_GRAYSCALE, cv::IMREAD_COLOR, cv::IMREAD_UNCHANGED}) {
      const Photo photo = read_photo(file, flags);
      EXPECT_EQ(photo.image.cols, 64) << orientation << " " << flags;
      EXPECT_EQ(photo.image.rows, 48) << orientation << " " << flags;
    }
  }
}

}  // namespace
}  // namespace antpose::io
