#include "antpose/io/photo_file.hpp"

#include <new>

#include <opencv2/imgcodecs.hpp>

#include "antpose/core/error.hpp"
#include "antpose/io/file_access.hpp"

namespace antpose::io {

Photo read_photo(const std::filesystem::path& file, int flags) {
  Photo photo;
  try {
    require_regular_file(file, kMaxPhotoBytes);
    photo.image = cv::imread(file.string(), flags);
    if (photo.image.empty()) photo.problem = "cannot be decoded: not a JPEG, PNG or TIFF photo, or truncated";
  } catch (const InputError& e) {
    photo.problem = e.detail();
  } catch (const cv::Exception& e) {
    // imread's own checks (a header claiming over 2^30 pixels) end in an exception.
    photo.problem = "cannot be decoded (" + e.err + ")";
  } catch (const std::bad_alloc&) {
    photo.problem = "cannot be decoded: its header claims more pixels than memory holds";
  }
  if (!photo.ok()) photo.image.release();
  return photo;
}

}  // namespace antpose::io
