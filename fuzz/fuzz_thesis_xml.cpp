// The thesis collection app's project (io/import.hpp): the input up to its first NUL byte is
// collection-proj.xml, the rest the sensor file it names; without a NUL the input is the sensor
// file of a fixed project.
#include <algorithm>

#include "antpose/io/import.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace antpose;
  const auto bytes = fuzz::view(data, size);
  const auto nul = bytes.find('\0');
  const std::string_view project =
      nul == std::string_view::npos ? std::string_view(
                                          "<project><collections><collection><index>0</index><time>1388835284.1</time>"
                                          "<sensor>sensor_0.xml</sensor></collection></collections></project>")
                                    : bytes.substr(0, nul);
  fuzz::write("thesis/collection-proj.xml", project);
  fuzz::write("thesis/sensor_0.xml", nul == std::string_view::npos ? bytes : bytes.substr(nul + 1));
  fuzz::expect_clean([&] {
    Diagnostics diagnostics;
    import_thesis_project(fuzz::scratch() / "thesis", diagnostics);
  });
  return 0;
}
