#include "antpose/registration/known_object_masks.hpp"

#include <algorithm>
#include <cmath>
#include <functional>

#include <opencv2/imgproc.hpp>

namespace antpose::registration {
namespace {

constexpr std::size_t kKept = 16;  // masked levels kept, the least recently used dropped first

std::size_t objects_hash(const SilhouetteView& v) {
  std::size_t h = 0;
  const auto mix = [&h](float x) { h ^= std::hash<float>{}(x) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2); };
  for (const auto* group : {&v.occluders, &v.background_edges}) {
    mix(static_cast<float>(group->size()));
    for (const auto& poly : *group) {
      mix(static_cast<float>(poly.size()));
      for (const auto& p : poly) mix(p.x), mix(p.y);
    }
  }
  return h;
}

}  // namespace

cv::Mat known_object_mask(const SilhouetteView& in, const Vec2& origin, cv::Size size, int level, double guard_px) {
  cv::Mat m = cv::Mat::zeros(size, CV_8UC1);
  const double s = std::ldexp(1.0, -level);
  constexpr int kShift = 2;  // quarter-pixel vertices
  const auto to_level = [&](const std::vector<cv::Point2f>& poly) {
    std::vector<cv::Point> out;
    for (const auto& p : poly)
      out.emplace_back(static_cast<int>(std::lround((p.x - origin.x()) * s * (1 << kShift))),
                       static_cast<int>(std::lround((p.y - origin.y()) * s * (1 << kShift))));
    return out;
  };
  for (const auto& poly : in.occluders)
    if (poly.size() >= 3) cv::fillPoly(m, std::vector<std::vector<cv::Point>>{to_level(poly)}, 255, cv::LINE_8, kShift);
  for (const auto& line : in.background_edges)
    if (line.size() >= 2)
      cv::polylines(m, std::vector<std::vector<cv::Point>>{to_level(line)}, false, 255, 1, cv::LINE_8, kShift);
  const int r = static_cast<int>(std::ceil(guard_px));
  cv::dilate(m, m, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1)));
  return m;
}

MaskedEdges masked_edges(cv::Mat mask, const cv::Mat& gx, const cv::Mat& gy) {
  MaskedEdges out{std::move(mask), gx, gy};
  if (cv::countNonZero(out.mask) > 0) {
    out.gx = gx.clone(), out.gy = gy.clone();
    out.gx.setTo(0, out.mask);
    out.gy.setTo(0, out.mask);
  }
  return out;
}

MaskedEdges KnownObjectMasks::masked(const SilhouetteView& view, const cv::Mat& gx, const cv::Mat& gy,
                                     const Vec2& origin, int level, double guard_px) {
  cv::Size whole_size;
  cv::Point at;
  gx.locateROI(whole_size, at);
  const cv::Rect sub(at, gx.size());
  const std::size_t objects = objects_hash(view);
  const std::lock_guard lock(mutex_);
  ++uses_;
  auto hit = std::find_if(kept_.begin(), kept_.end(), [&](const Kept& k) {
    return k.source_gx.datastart == gx.datastart && k.level == level && k.guard_px == guard_px && k.objects == objects;
  });
  if (hit == kept_.end()) {
    const auto whole = [&](cv::Mat m) {
      return m.adjustROI(at.y, whole_size.height - at.y - m.rows, at.x, whole_size.width - at.x - m.cols);
    };
    const cv::Mat whole_gx = whole(gx), whole_gy = whole(gy);
    const Vec2 whole_origin = origin - std::ldexp(1.0, level) * Vec2(at.x, at.y);
    Kept k;
    k.level = level, k.guard_px = guard_px, k.objects = objects, k.source_gx = whole_gx;
    k.whole = masked_edges(known_object_mask(view, whole_origin, whole_size, level, guard_px), whole_gx, whole_gy);
    if (kept_.size() >= kKept)
      kept_.erase(std::min_element(kept_.begin(), kept_.end(),
                                   [](const Kept& a, const Kept& b) { return a.last_use < b.last_use; }));
    kept_.push_back(std::move(k));
    ++drawn_;
    hit = kept_.end() - 1;
  }
  hit->last_use = uses_;
  return {hit->whole.mask(sub), hit->whole.gx(sub), hit->whole.gy(sub)};
}

std::size_t KnownObjectMasks::drawn() const {
  const std::lock_guard lock(mutex_);
  return drawn_;
}

}  // namespace antpose::registration
