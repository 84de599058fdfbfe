#include "antpose/registration/edge_distance.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <opencv2/imgproc.hpp>

#include "antpose/core/rounding.hpp"

namespace antpose::registration {
namespace {

// Immerkær's estimate of the noise σ (grey levels): the mean absolute response of the mask
// [1 −2 1; −2 4 −2; 1 −2 1], which cancels every plane and most of a smooth image, times √(π/2)/6.
double noise_sigma(const cv::Mat& grey) {
  if (grey.rows < 3 || grey.cols < 3) return 0.0;
  const cv::Mat kernel = (cv::Mat_<float>(3, 3) << 1, -2, 1, -2, 4, -2, 1, -2, 1);
  cv::Mat response;
  cv::filter2D(grey, response, CV_32F, kernel, cv::Point(-1, -1), 0.0, cv::BORDER_REPLICATE);
  const cv::Mat inner = cv::abs(response(cv::Rect(1, 1, grey.cols - 2, grey.rows - 2)));
  return std::sqrt(std::numbers::pi / 2.0) * cv::mean(inner)[0] / 6.0;
}

int bin_of(double angle_rad, int bins) {
  double a = std::fmod(angle_rad, std::numbers::pi);
  if (a < 0) a += std::numbers::pi;
  return std::min(bins - 1, static_cast<int>(a / std::numbers::pi * bins));
}

}  // namespace

OptionProblems EdgeDistanceOptions::Check() const {
  OptionProblems p;
  p.require(orientation_bins >= 1 && orientation_bins <= 36, "orientation_bins", "1..36");
  p.require(low_noise_sigmas > 0 && high_noise_sigmas >= low_noise_sigmas, "low_noise_sigmas, high_noise_sigmas",
            "0 < low ≤ high");
  p.require(min_noise_grey >= 0, "min_noise_grey", "≥ 0");
  p.require(blur_sigma_px >= 0, "blur_sigma_px", "≥ 0");
  return p;
}

EdgeDistance::EdgeDistance(const cv::Mat& image, cv::Rect area, double scale,
                           const std::vector<std::vector<cv::Point2f>>& occluders, const EdgeDistanceOptions& o)
    : area_(area & cv::Rect(0, 0, image.cols, image.rows)), scale_(scale) {
  throw_unless_ok(o.Check(), "EdgeDistanceOptions");
  if (area_.width < 4 || area_.height < 4 || !(scale > 0 && scale <= 1)) {
    area_ = {};
    return;
  }
  cv::Mat grey;
  cv::resize(image(area_), grey, cv::Size(), scale, scale, cv::INTER_AREA);
  if (o.blur_sigma_px > 0) cv::GaussianBlur(grey, grey, cv::Size(), o.blur_sigma_px);
  noise_grey_ = std::max(o.min_noise_grey, noise_sigma(grey));
  cv::Mat dx, dy;
  cv::Sobel(grey, dx, CV_16S, 1, 0, 3);
  cv::Sobel(grey, dy, CV_16S, 0, 1, 3);
  // The 3×3 Sobel kernel's norm is √12: its response to white noise of σ has that σ times √12.
  const double gradient_noise = std::sqrt(12.0) * noise_grey_;
  cv::Canny(dx, dy, edges_, o.low_noise_sigmas * gradient_noise, o.high_noise_sigmas * gradient_noise, true);
  mask_ = cv::Mat::zeros(grey.size(), CV_8UC1);
  for (const auto& poly : occluders) {
    std::vector<cv::Point> p;
    for (const auto& q : poly)
      p.emplace_back(static_cast<int>(std::lround((q.x - area_.x) * scale)),
                     static_cast<int>(std::lround((q.y - area_.y) * scale)));
    if (p.size() >= 3) cv::fillPoly(mask_, std::vector<std::vector<cv::Point>>{p}, 255);
  }
  edges_.setTo(0, mask_);
  std::vector<cv::Mat> by_bin(static_cast<std::size_t>(o.orientation_bins));
  for (auto& b : by_bin) b = cv::Mat(grey.size(), CV_8UC1, cv::Scalar(255));
  for (int y = 0; y < grey.rows; ++y)
    for (int x = 0; x < grey.cols; ++x)
      if (edges_.at<std::uint8_t>(y, x)) {
        const double angle = std::atan2(dy.at<std::int16_t>(y, x), dx.at<std::int16_t>(y, x));
        by_bin[static_cast<std::size_t>(bin_of(angle, o.orientation_bins))].at<std::uint8_t>(y, x) = 0;
      }
  std::vector<cv::Mat> own(by_bin.size());
  for (std::size_t k = 0; k < by_bin.size(); ++k)
    cv::distanceTransform(by_bin[k], own[k], cv::DIST_L2, cv::DIST_MASK_PRECISE);
  // A look-up takes its bin or a bin either side: their minimum, made once, serves each look-up
  // with one read instead of three (the outline search makes millions).
  const std::size_t bins = own.size();
  for (std::size_t k = 0; k < bins; ++k) {
    cv::Mat d = own[k].clone();
    if (bins > 2) {
      cv::min(d, own[(k + 1) % bins], d);
      cv::min(d, own[(k + bins - 1) % bins], d);
    }
    distance_.push_back(d);
  }
}

int EdgeDistance::bin(const Vec2& normal) const {
  return bin_of(std::atan2(normal.y(), normal.x()), std::max(1, static_cast<int>(distance_.size())));
}

double EdgeDistance::distance(const Vec2& p_px, int b, EdgeLookup& status) const {
  status = EdgeLookup::kOutside;
  if (distance_.empty()) return 0.0;
  const int x = round_half_away((p_px.x() - area_.x) * scale_);
  const int y = round_half_away((p_px.y() - area_.y) * scale_);
  if (x < 0 || y < 0 || x >= mask_.cols || y >= mask_.rows) return 0.0;
  if (mask_.at<std::uint8_t>(y, x)) {
    status = EdgeLookup::kMasked;
    return 0.0;
  }
  status = EdgeLookup::kMeasured;
  return distance_[static_cast<std::size_t>(b)].at<float>(y, x);
}

}  // namespace antpose::registration
