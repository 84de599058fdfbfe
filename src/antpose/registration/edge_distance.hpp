// Where a photo's edges are, as oriented distance maps: the data of chamfer matching (Barrow et
// al., IJCAI 1977), with the edges split by direction so that a model's outline is matched only
// to edges running its way (Olson & Huttenlocher, IEEE TIP 6(1), 1997; Shotton, Blake & Cipolla,
// PAMI 30(7), 2008).
//
// A region of the photo is resized by `scale`, its edges found by Canny (non-maximum suppression
// and hysteresis) with thresholds set from the region's own noise (Immerkær, CVIU 64(2), 1996:
// σ from the mean absolute response of a Laplacian difference mask), so that a pale radome's
// faint outline against a bright sky is kept where it rises above the noise, whatever the light.
// Each edge pixel falls into one of `orientation_bins` bins of its gradient direction (mod 180°);
// one Euclidean distance transform per bin gives the distance to the nearest edge of that
// direction. Known nearer objects (the board) are masked: a look-up there says so.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

#include "antpose/core/check.hpp"
#include "antpose/geometry/rotation.hpp"

namespace antpose::registration {

struct EdgeDistanceOptions {
  int orientation_bins = 6;
  double low_noise_sigmas = 3.0;  // Canny's hysteresis thresholds, in σ of the gradient's noise
  double high_noise_sigmas = 6.0;
  double min_noise_grey = 0.5;  // a floor for σ (grey levels): JPEG flattens smooth areas to 0
  double blur_sigma_px = 1.0;   // Gaussian before the edges, px of the map
  OptionProblems Check() const;
};

/// The outcome of one look-up.
enum class EdgeLookup { kMeasured, kMasked, kOutside };

class EdgeDistance {
 public:
  /// `image` CV_8UC1 (the whole photo, as taken); `area` the part to map (full-resolution px,
  /// clipped to the image); `scale` in (0, 1] the map's size over the area's; `occluders` image
  /// polygons (full-resolution px) of known nearer objects. An empty area gives a map where every
  /// look-up is kOutside.
  EdgeDistance(const cv::Mat& image, cv::Rect area, double scale,
               const std::vector<std::vector<cv::Point2f>>& occluders, const EdgeDistanceOptions& options);

  /// The direction bin of an outline whose normal (image) is `normal`.
  int bin(const Vec2& normal) const;
  /// Distance (px of the map) from the full-resolution point `p_px` to the nearest edge whose
  /// gradient runs along the outline's normal (its `bin`, or a bin either side), and how it went.
  double distance(const Vec2& p_px, int bin, EdgeLookup& status) const;
  double scale() const { return scale_; }
  /// The σ of the region's grey-level noise (Immerkær) the thresholds were set from.
  double noise_grey() const { return noise_grey_; }
  /// The edge pixels found (CV_8UC1, 255 on an edge), for reports and tests.
  const cv::Mat& edges() const { return edges_; }

 private:
  cv::Rect area_;
  double scale_ = 1.0, noise_grey_ = 0.0;
  cv::Mat edges_, mask_;
  std::vector<cv::Mat> distance_;  // per bin, CV_32F: to the nearest edge of that bin or a bin either side
};

}  // namespace antpose::registration
