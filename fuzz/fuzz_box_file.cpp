// The thesis's box file (model/box_file.hpp): eight labelled corners, in metres or millimetres.
#include "antpose/model/box_file.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace antpose;
  const std::string text(fuzz::view(data, size));
  fuzz::expect_clean([&] { model::parse_box_file(text, "antenna.box", model::Units::kMetres); });
  fuzz::expect_clean([&] { model::parse_box_file(text, "antenna.box", model::Units::kMillimetres); });
  return 0;
}
