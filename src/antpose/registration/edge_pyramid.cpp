#include "antpose/registration/edge_pyramid.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "antpose/camera/edge_search.hpp"

namespace antpose::registration {

cv::Rect align_to_grid(const cv::Rect& crop, int grid, const cv::Rect& bounds) {
  const auto down = [grid](int v) { return static_cast<int>(std::floor(static_cast<double>(v) / grid)) * grid; };
  const auto up = [grid](int v) { return static_cast<int>(std::ceil(static_cast<double>(v) / grid)) * grid; };
  const int x0 = down(crop.x), y0 = down(crop.y);
  return cv::Rect(x0, y0, up(crop.x + crop.width) - x0, up(crop.y + crop.height) - y0) & bounds;
}

EdgePyramid::EdgePyramid(cv::Mat image, EdgePyramidSettings settings) : image_(std::move(image)), settings_(settings) {
  if (image_.type() != CV_8UC1) throw std::invalid_argument("EdgePyramid: the photo must be CV_8UC1");
  if (!(settings_.growth >= 0) || settings_.max_crops < 1 || settings_.min_levels < 1 || settings_.min_levels > 12)
    throw std::invalid_argument("EdgePyramid: growth must be ≥ 0, max_crops ≥ 1 and min_levels 1..12");
}

bool EdgePyramid::serves(double gamma, double smoothing_sigma_px) const {
  return gamma == settings_.gamma && smoothing_sigma_px == settings_.smoothing_sigma_px;
}

std::size_t EdgePyramid::crops_computed() const {
  const std::lock_guard lock(mutex_);
  return computed_;
}

EdgeLevels EdgePyramid::compute(const cv::Rect& aligned, int levels) const {
  EdgeLevels out;
  out.crop = aligned;
  cv::Mat level = camera::linear_intensity(image_(aligned), settings_.gamma);
  for (int l = 0; l < levels; ++l) {
    if (l > 0) {
      cv::Mat down;
      cv::pyrDown(level, down);
      level = down;
    }
    auto [gx, gy] = camera::smoothed_gradients(level, settings_.smoothing_sigma_px);
    out.gx.push_back(gx);
    out.gy.push_back(gy);
  }
  return out;
}

EdgeLevels EdgePyramid::gradients(const cv::Rect& crop, int levels, double gamma, double smoothing_sigma_px) {
  if (levels < 1 || levels > 12) throw std::invalid_argument("EdgePyramid::gradients: levels must be 1..12");
  if (!serves(gamma, smoothing_sigma_px))
    throw std::invalid_argument("EdgePyramid::gradients: the pyramid was made with another gamma or smoothing");
  const int grid = 1 << (levels - 1);
  const cv::Rect photo(0, 0, image_.cols, image_.rows);
  const cv::Rect asked = align_to_grid(crop, grid, photo);
  if (asked.empty()) return {};
  const std::lock_guard lock(mutex_);
  ++uses_;
  auto hit = std::find_if(kept_.begin(), kept_.end(), [&](const Kept& k) {
    return static_cast<int>(k.levels.gx.size()) >= levels && (k.levels.crop & asked) == asked &&
           (asked.x - k.levels.crop.x) % grid == 0 && (asked.y - k.levels.crop.y) % grid == 0;
  });
  if (hit == kept_.end()) {
    const int keep_levels = std::max(levels, settings_.min_levels);
    const int gx = static_cast<int>(std::ceil(settings_.growth * asked.width));
    const int gy = static_cast<int>(std::ceil(settings_.growth * asked.height));
    const cv::Rect grown =
        align_to_grid(cv::Rect(asked.x - gx, asked.y - gy, asked.width + 2 * gx, asked.height + 2 * gy),
                      1 << (keep_levels - 1), photo);
    if (kept_.size() >= settings_.max_crops)
      kept_.erase(std::min_element(kept_.begin(), kept_.end(),
                                   [](const Kept& a, const Kept& b) { return a.last_use < b.last_use; }));
    kept_.push_back({compute(grown, keep_levels), 0});
    ++computed_;
    hit = kept_.end() - 1;
  }
  hit->last_use = uses_;
  EdgeLevels out;
  out.crop = asked;
  for (int l = 0; l < levels; ++l) {
    // Level l of a crop starting on the grid: (x − x₀)/2^l exactly, ⌈w/2^l⌉ wide like pyrDown's.
    const int s = 1 << l;
    const cv::Mat& kx = hit->levels.gx[static_cast<std::size_t>(l)];
    const cv::Rect sub((asked.x - hit->levels.crop.x) / s, (asked.y - hit->levels.crop.y) / s,
                       (asked.width + s - 1) / s, (asked.height + s - 1) / s);
    const cv::Rect within = sub & cv::Rect(0, 0, kx.cols, kx.rows);
    out.gx.push_back(kx(within));
    out.gy.push_back(hit->levels.gy[static_cast<std::size_t>(l)](within));
  }
  return out;
}

}  // namespace antpose::registration
