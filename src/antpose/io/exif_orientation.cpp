#include "antpose/io/exif_orientation.hpp"

#include <stdexcept>
#include <string>

namespace antpose::io {
namespace {

void require_orientation(int orientation) {
  if (!is_exif_orientation(orientation))
    throw std::invalid_argument("EXIF orientation " + std::to_string(orientation) + " is not within 1–8");
}

bool swaps_sides(int orientation) { return orientation >= 5; }

}  // namespace

cv::Size upright_size(const cv::Size& stored, int orientation) {
  require_orientation(orientation);
  return swaps_sides(orientation) ? cv::Size(stored.height, stored.width) : stored;
}

cv::Rect stored_rect(const cv::Rect& upright, const cv::Size& stored, int orientation) {
  require_orientation(orientation);
  // Edge coordinates: a point (u, v) of the upright photo is (x, y) in the stored one, W×H.
  const int W = stored.width, H = stored.height;
  const int u0 = upright.x, u1 = upright.x + upright.width, v0 = upright.y, v1 = upright.y + upright.height;
  switch (orientation) {
    case 1:
      return upright;
    case 2:
      return {W - u1, v0, upright.width, upright.height};  // x = W − u
    case 3:
      return {W - u1, H - v1, upright.width, upright.height};  // x = W − u, y = H − v
    case 4:
      return {u0, H - v1, upright.width, upright.height};  // y = H − v
    case 5:
      return {v0, u0, upright.height, upright.width};  // x = v, y = u
    case 6:
      return {v0, H - u1, upright.height, upright.width};  // x = v, y = H − u
    case 7:
      return {W - v1, H - u1, upright.height, upright.width};  // x = W − v, y = H − u
    default:
      return {W - v1, u0, upright.height, upright.width};  // 8: x = W − v, y = u
  }
}

cv::Mat upright_image(const cv::Mat& stored, int orientation) {
  require_orientation(orientation);
  cv::Mat out;
  switch (orientation) {
    case 1:
      return stored;
    case 2:
      cv::flip(stored, out, 1);
      break;
    case 3:
      cv::rotate(stored, out, cv::ROTATE_180);
      break;
    case 4:
      cv::flip(stored, out, 0);
      break;
    case 5:
      cv::transpose(stored, out);
      break;
    case 6:
      cv::rotate(stored, out, cv::ROTATE_90_CLOCKWISE);
      break;
    case 7:
      cv::transpose(stored, out), cv::rotate(out, out, cv::ROTATE_180);
      break;
    default:
      cv::rotate(stored, out, cv::ROTATE_90_COUNTERCLOCKWISE);
      break;  // 8
  }
  return out;
}

}  // namespace antpose::io
