// Decoding a photo of a capture, where one bad file is a refused photo, not a failed command.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>

#include <opencv2/core.hpp>

namespace antpose::io {

/// The largest photo file antpose decodes: a 200 MP phone's JPEG is about 60 MB.
inline constexpr std::uintmax_t kMaxPhotoBytes = std::uintmax_t{256} << 20;

/// A decoded photo, or why it could not be had.
struct Photo {
  cv::Mat image;        // empty when `problem` is set
  std::string problem;  // "is a folder, expected a file", "cannot be decoded …"
  bool ok() const { return problem.empty(); }
};

/// Decodes `file` with OpenCV's imread `flags`. A file that is missing, not a regular file, over
/// kMaxPhotoBytes, or that OpenCV refuses (not an image, truncated, a header claiming more
/// pixels than OpenCV accepts) gives its reason in Photo::problem; it never throws for the file.
Photo read_photo(const std::filesystem::path& file, int flags);

}  // namespace antpose::io
