// Locating an object's outline in a photo: gradients in linear intensity, and the 1-D search
// along a predicted contour's normal for the nearest strong edge (Harris, "Tracking with rigid
// models", Active Vision 1992; Drummond & Cipolla, PAMI 24(7), 2002). Used by the antenna's
// silhouette refinement and the mast's outline.
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "antpose/geometry/rotation.hpp"

namespace antpose::camera {

/// The 8-bit photo (or a crop of it) as CV_32F linear intensity, 0–255: the encoding's gamma
/// undone (sRGB ≈ 2.2; 0 keeps the stored values). In encoded values a blurred step's steepest
/// point moves towards its dark side, which biases an outline's position by a fraction of a pixel.
cv::Mat linear_intensity(const cv::Mat& grey8, double gamma);

/// Gradient images (d/dx, d/dy, grey levels per px) of `image` (CV_32F) after a Gaussian of
/// `sigma_px`.
std::pair<cv::Mat, cv::Mat> smoothed_gradients(const cv::Mat& image, double sigma_px);

/// The search line of nearest_edge, px: from `behind_px` against the normal to `ahead_px` along it.
struct EdgeSearchSpan {
  double behind_px = 0, ahead_px = 0;
  static EdgeSearchSpan symmetric(double half_range_px) { return {half_range_px, half_range_px}; }
};

/// The signed distance (px of the gradient images, along `normal`) from `centre` to the nearest
/// strong edge on the search line `span`: a local maximum of the gradient's component along the
/// normal, at least `min_gradient` and at least `relative` × the strongest on the line, located
/// to sub-pixel by a parabola. Searched in steps of `step_px` (bilinear), gradients of 0 (masked
/// parts of the image) are never edges. nullopt when there is none. `scratch` avoids a
/// reallocation per call.
std::optional<double> nearest_edge(const cv::Mat& gx, const cv::Mat& gy, const Vec2& centre, const Vec2& normal,
                                   EdgeSearchSpan span, double min_gradient, std::vector<double>& scratch,
                                   double relative = 0.5, double step_px = 0.5);

/// The gradient's component along `normal` at `z` (px): the bilinear samples of the CV_32F
/// gradient images gx and gy (0 outside), weighted once for both.
double gradient_along(const cv::Mat& gx, const cv::Mat& gy, const Vec2& z, const Vec2& normal);

}  // namespace antpose::camera
