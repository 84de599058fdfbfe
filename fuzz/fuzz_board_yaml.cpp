// board.yaml (camera/board.hpp): chessboards, circle grids, ChArUco boards and their sizes.
#include "antpose/camera/board.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace antpose;
  fuzz::expect_clean([&] { camera::parse_board(std::string(fuzz::view(data, size)), "board.yaml"); });
  return 0;
}
