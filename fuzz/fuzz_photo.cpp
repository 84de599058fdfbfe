// Photos (io/photo_file.hpp): the header read by Exiv2 and the pixels decoded by OpenCV, as JPEG
// and as PNG. Neither may throw for the file: a bad photo is a reason.
#include <opencv2/imgcodecs.hpp>

#include "antpose/io/photo_file.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace antpose;
  const auto bytes = fuzz::view(data, size);
  for (const char* name : {"photo.jpg", "photo.png"}) {
    const auto file = fuzz::write(name, bytes);
    const io::PhotoHeader header = io::read_photo_header(file);
    if (header.ok() && (header.width_px <= 0 || header.height_px <= 0)) __builtin_trap();
    // Decoded only where the header claims a size a phone makes (as board_poses does before decoding).
    if (header.ok() && static_cast<double>(header.width_px) * header.height_px <= 50e6)
      io::read_photo(file, cv::IMREAD_GRAYSCALE);
  }
  return 0;
}
