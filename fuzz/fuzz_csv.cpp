// The CSV / CSV.GZ reader (io/csv.hpp): bytes starting with gzip's magic go through zlib.
#include "antpose/io/csv.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace antpose;
  const bool gzip = size >= 2 && data[0] == 0x1f && data[1] == 0x8b;
  const auto file =
      fuzz::write(gzip ? "sensors/accelerometer.csv.gz" : "sensors/accelerometer.csv", fuzz::view(data, size));
  fuzz::expect_clean([&] { io::read_csv(file); });
  return 0;
}
