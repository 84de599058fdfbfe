// A World Magnetic Model coefficient file (geomag/wmm.hpp), then the model evaluated with it.
#include "antpose/geomag/wmm.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace antpose;
  fuzz::expect_clean([&] {
    const auto model = geomag::MagneticModel::from_cof_text(fuzz::view(data, size), "WMM.COF");
    model.evaluate(48.85, 2.35, 0.1, model.epoch() + 1.0);
  });
  return 0;
}
