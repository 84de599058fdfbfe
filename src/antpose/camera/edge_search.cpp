#include "antpose/camera/edge_search.hpp"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace antpose::camera {

cv::Mat linear_intensity(const cv::Mat& grey8, double gamma) {
  cv::Mat out;
  if (gamma > 0) {
    cv::Mat lut(1, 256, CV_32F);
    for (int k = 0; k < 256; ++k) lut.at<float>(k) = static_cast<float>(255.0 * std::pow(k / 255.0, gamma));
    cv::LUT(grey8, lut, out);
  } else {
    grey8.convertTo(out, CV_32F);
  }
  return out;
}

std::pair<cv::Mat, cv::Mat> smoothed_gradients(const cv::Mat& image, double sigma_px) {
  cv::Mat f, gx, gy;
  cv::GaussianBlur(image, f, cv::Size(), sigma_px);
  cv::Sobel(f, gx, CV_32F, 1, 0, 3, 1.0 / 8.0);
  cv::Sobel(f, gy, CV_32F, 0, 1, 3, 1.0 / 8.0);
  return {gx, gy};
}

double gradient_along(const cv::Mat& gx, const cv::Mat& gy, const Vec2& z, const Vec2& normal) {
  const int x0 = static_cast<int>(std::floor(z.x())), y0 = static_cast<int>(std::floor(z.y()));
  if (x0 < 0 || y0 < 0 || x0 + 1 >= gx.cols || y0 + 1 >= gx.rows) return 0.0;
  const float fx = static_cast<float>(z.x() - x0), fy = static_cast<float>(z.y() - y0);
  const auto sample = [&](const cv::Mat& m) {
    const float* r0 = m.ptr<float>(y0);
    const float* r1 = m.ptr<float>(y0 + 1);
    return (1 - fy) * ((1 - fx) * r0[x0] + fx * r0[x0 + 1]) + fy * ((1 - fx) * r1[x0] + fx * r1[x0 + 1]);
  };
  return sample(gx) * normal.x() + sample(gy) * normal.y();
}

std::optional<double> nearest_edge(const cv::Mat& gx, const cv::Mat& gy, const Vec2& centre, const Vec2& normal,
                                   EdgeSearchSpan span, double min_gradient, std::vector<double>& g, double relative,
                                   double step_px) {
  // g[i] is the gradient (i - behind) steps along the normal.
  const int behind = static_cast<int>(std::ceil(std::max(0.0, span.behind_px) / step_px));
  const int ahead = static_cast<int>(std::ceil(std::max(0.0, span.ahead_px) / step_px));
  g.assign(static_cast<std::size_t>(behind + ahead + 1), 0.0);
  double gmax = 0;
  for (int i = -behind; i <= ahead; ++i) {
    const Vec2 z = centre + (i * step_px) * normal;
    g[i + behind] = std::abs(gradient_along(gx, gy, z, normal));
    gmax = std::max(gmax, g[i + behind]);
  }
  if (gmax < min_gradient) return std::nullopt;
  int best = -1;
  for (int i = 1; i + 1 < static_cast<int>(g.size()); ++i) {
    if (g[i] < relative * gmax || g[i] < min_gradient || g[i] < g[i - 1] || g[i] < g[i + 1]) continue;
    if (best < 0 || std::abs(i - behind) < std::abs(best - behind)) best = i;
  }
  if (best < 0) return std::nullopt;
  const double den = g[best - 1] - 2 * g[best] + g[best + 1];
  const double sub = den < 0 ? std::clamp(0.5 * (g[best - 1] - g[best + 1]) / den, -0.5, 0.5) : 0.0;
  return ((best - behind) + sub) * step_px;
}

}  // namespace antpose::camera
