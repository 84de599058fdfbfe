#include "antpose/io/photo_file.hpp"

#include <algorithm>
#include <exception>
#include <fstream>
#include <mutex>
#include <new>
#include <string_view>

#include <exiv2/exiv2.hpp>
#include <opencv2/imgcodecs.hpp>

#include "antpose/core/error.hpp"
#include "antpose/io/file_access.hpp"

namespace antpose::io {
namespace {

using namespace std::string_view_literals;

constexpr const char* kNotAPhoto = "not a JPEG, PNG or TIFF photo";

// Whether the file starts as a JPEG, PNG or TIFF does. OpenCV's imread would otherwise take any
// decoder whose signature it finds anywhere it looks (Debian's build has GDAL and GDCM: "DICM"
// at byte 128 makes a DICOM file, whose reader allocates what its lengths claim).
bool has_photo_signature(const std::filesystem::path& file) {
  char head[8] = {};
  std::ifstream in(file, std::ios::binary);
  in.read(head, sizeof head);
  const std::string_view h(head, static_cast<std::size_t>(in.gcount()));
  return h.starts_with("\xFF\xD8\xFF"sv) || h.starts_with("\x89PNG\r\n\x1A\n"sv) || h.starts_with("II*\0"sv) ||
         h.starts_with("MM\0*"sv);
}

}  // namespace

Photo read_photo(const std::filesystem::path& file, int flags) {
  Photo photo;
  try {
    require_regular_file(file, kMaxPhotoBytes);
    if (!has_photo_signature(file)) {
      photo.problem = std::string("cannot be decoded: ") + kNotAPhoto;
      return photo;
    }
    photo.image = cv::imread(file.string(), flags | cv::IMREAD_IGNORE_ORIENTATION);
    if (photo.image.empty()) photo.problem = std::string("cannot be decoded: ") + kNotAPhoto + ", or truncated";
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

namespace {

// Exiv2 logs a damaged file's details to stderr itself; the caller gets them as the reason.
// Its XMP parser must be set up once before threads read files (Exiv2::XmpParser::initialize).
void set_up_exiv2() {
  static std::once_flag once;
  std::call_once(once, [] {
    Exiv2::LogMsg::setLevel(Exiv2::LogMsg::mute);
    Exiv2::XmpParser::initialize();
  });
}

}  // namespace

PhotoHeader read_photo_header(const std::filesystem::path& file) {
  set_up_exiv2();
  PhotoHeader header;
  try {
    require_regular_file(file, kMaxPhotoBytes);
    if (!has_photo_signature(file)) {
      header.problem = kNotAPhoto;
      return header;
    }
    auto image = Exiv2::ImageFactory::open(file.string());
    image->readMetadata();
    header.width_px = image->pixelWidth();
    header.height_px = image->pixelHeight();
    const auto& exif = image->exifData();
    if (const auto tag = exif.findKey(Exiv2::ExifKey("Exif.Image.Orientation")); tag != exif.end()) {
      const long value = tag->toLong();
      if (value >= 1 && value <= 8) header.exif_orientation = static_cast<int>(value);
    }
    if (header.width_px <= 0 || header.height_px <= 0) header.problem = "its header gives no size";
  } catch (const InputError& e) {
    header.problem = e.detail();
  } catch (const std::exception& e) {  // Exiv2::AnyError: not an image format Exiv2 knows, or damaged
    header.problem = std::string("its header cannot be read (") + e.what() + ")";
  }
  return header;
}

std::vector<PhotoHeader> read_photo_headers(const Capture& capture) {
  std::vector<PhotoHeader> headers;
  for (const auto& shot : capture.shots) headers.push_back(read_photo_header(capture.root / shot.image));
  return headers;
}

std::optional<cv::Size> common_photo_size(const std::vector<PhotoHeader>& headers) {
  std::vector<std::pair<cv::Size, std::size_t>> counts;  // in order of first appearance
  for (const auto& header : headers) {
    if (!header.ok()) continue;
    const cv::Size size(header.width_px, header.height_px);
    const auto at = std::find_if(counts.begin(), counts.end(), [&](const auto& c) { return c.first == size; });
    if (at == counts.end())
      counts.emplace_back(size, 1);
    else
      ++at->second;
  }
  if (counts.empty()) return std::nullopt;
  return std::max_element(counts.begin(), counts.end(),
                          [](const auto& a, const auto& b) { return a.second < b.second; })
      ->first;
}

}  // namespace antpose::io
