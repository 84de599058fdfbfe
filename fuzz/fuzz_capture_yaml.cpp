// capture.yaml and the checks of a whole capture (io/capture.hpp): the fuzzed metadata beside
// three valid streams.
#include "antpose/io/capture.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace antpose;
  static const bool streams_written = [] {
    for (const char* name : {"accelerometer", "gyroscope", "magnetometer"})
      fuzz::write(std::string("capture/sensors/") + name + ".csv",
                  "t,x,y,z\n0,0.1,0.2,9.8\n0.01,0.1,0.2,9.8\n0.02,0.1,0.2,9.8\n");
    return true;
  }();
  (void)streams_written;
  fuzz::write("capture/capture.yaml", fuzz::view(data, size));
  fuzz::expect_clean([&] {
    Diagnostics diagnostics;
    read_capture(fuzz::scratch() / "capture", diagnostics);
  });
  return 0;
}
