// Decoding a photo of a capture, where one bad file is a refused photo, not a failed command.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "antpose/io/capture.hpp"

namespace antpose::io {

/// The largest photo file antpose decodes: a 200 MP phone's JPEG is about 60 MB.
inline constexpr std::uintmax_t kMaxPhotoBytes = std::uintmax_t{256} << 20;

/// A decoded photo, or why it could not be had.
struct Photo {
  cv::Mat image;        // empty when `problem` is set
  std::string problem;  // "is a folder, expected a file", "cannot be decoded …"
  bool ok() const { return problem.empty(); }
};

/// Decodes `file` with OpenCV's imread `flags`, always as stored: an EXIF Orientation tag is not
/// applied (OpenCV would apply it for some flags and not for others), because the intrinsics, the
/// board's detection and the reconstruction all work in the sensor's pixels; the tag matters only
/// for showing a photo upright and for coordinates read off an upright one (PhotoHeader). A file that is missing, not a regular file, over
/// kMaxPhotoBytes, or that OpenCV refuses (not an image, truncated, a header claiming more
/// pixels than OpenCV accepts) gives its reason in Photo::problem; it never throws for the file.
Photo read_photo(const std::filesystem::path& file, int flags);

/// What a photo's header says, read without decoding its pixels (Exiv2).
struct PhotoHeader {
  int width_px = 0, height_px = 0;  // as stored, before any EXIF orientation
  int exif_orientation = 1;         // EXIF Orientation 1–8 (1: upright as stored, or no tag)
  std::string problem;              // as Photo::problem; also a header Exiv2 cannot read
  bool ok() const { return problem.empty(); }
};

/// The header of `file`: its stored size, in microseconds where decoding takes a second. The size
/// is what the file claims; a photo whose claim is false is refused when it is decoded.
PhotoHeader read_photo_header(const std::filesystem::path& file);

/// The header of every photo of the capture, in shot order.
std::vector<PhotoHeader> read_photo_headers(const Capture& capture);

/// The size most of the photos share, from their headers; nullopt where no header can be read.
/// Ties go to the size of the earlier photo. One file whose header claims another size (a resized
/// copy, a damaged header) is then refused alone, by the caller's size check, instead of deciding
/// the size for all.
std::optional<cv::Size> common_photo_size(const std::vector<PhotoHeader>& headers);

}  // namespace antpose::io
