// Antenna meshes (model/mesh.hpp): the same bytes as OBJ and as PLY (ASCII or binary).
#include "antpose/model/mesh.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace antpose;
  const auto bytes = fuzz::view(data, size);
  fuzz::expect_clean([&] { model::parse_obj(bytes, "antenna.obj"); });
  fuzz::expect_clean([&] { model::parse_ply(bytes, "antenna.ply"); });
  return 0;
}
