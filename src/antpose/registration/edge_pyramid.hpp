// The edge images of one photo for the outline refinement (silhouette.hpp), computed once per
// crop and shared by every refinement and evaluation in that photo.
//
// Preparing a crop (the photo's gamma undone, a Gaussian pyramid, smoothed gradients on every
// level) costs about as much as the descent that reads it, and a registration descends from
// dozens of starts, and scores as many poses, in the same photos. The pyramid keeps the last few
// crops it computed, each grown beyond what was asked (`growth`) so that the next start nearby
// is served from it.
//
// Crops are aligned to the coarsest level's pixel grid (2^(levels−1) px): every level of an
// aligned crop inside a kept one is then an exact sub-image of the kept level, and the images a
// descent sees do not depend on which crop was asked for first. Away from its border a sub-image
// equals the crop computed alone; near it, it holds the photo's true gradients where a crop of
// its own would reflect its border. Thread-safe.
#pragma once

#include <cstddef>
#include <mutex>
#include <vector>

#include <opencv2/core.hpp>

namespace antpose::registration {

struct EdgeLevels {
  cv::Rect crop;                // full-resolution px, aligned (see the file comment)
  std::vector<cv::Mat> gx, gy;  // CV_32F per level: d/dx, d/dy of the linear intensity, smoothed
};

struct EdgePyramidSettings {
  double gamma = 2.2;               // photo encoding undone (camera::linear_intensity); 0: as stored
  double smoothing_sigma_px = 1.0;  // Gaussian before the gradient, per level
  /// Each computed crop is grown by this share of its size on every side (0: as asked), so that
  /// crops asked for nearby are served from it.
  double growth = 0.25;
  /// Each computed crop has at least this many levels, so that a later descent through a deeper
  /// pyramid is served from it too.
  int min_levels = 4;
  std::size_t max_crops = 2;  // crops kept, the least recently used dropped first

  /// One crop as asked, nothing kept for later: a single refinement's own preparation.
  static EdgePyramidSettings single_use(double gamma, double smoothing_sigma_px) {
    return {gamma, smoothing_sigma_px, 0.0, 1, 1};
  }
};

class EdgePyramid {
 public:
  /// `image`: CV_8UC1, the photo as taken (shared, not copied).
  explicit EdgePyramid(cv::Mat image, EdgePyramidSettings settings = {});

  /// `crop` (full-resolution px) expanded to the 2^(levels−1) grid and clipped to the photo, and
  /// its gradients on levels 0..levels−1 (level l: 2^−l of full resolution), as sub-images of a
  /// kept crop. Empty levels when the crop misses the photo.
  EdgeLevels gradients(const cv::Rect& crop, int levels, double gamma, double smoothing_sigma_px);

  /// Whether this pyramid serves the given preparation (else a caller computes its own).
  bool serves(double gamma, double smoothing_sigma_px) const;
  std::size_t crops_computed() const;  // over its lifetime (for tests and benchmarks)

 private:
  struct Kept {
    EdgeLevels levels;
    std::size_t last_use = 0;
  };
  EdgeLevels compute(const cv::Rect& aligned, int levels) const;

  cv::Mat image_;
  EdgePyramidSettings settings_;
  mutable std::mutex mutex_;
  std::vector<Kept> kept_;
  std::size_t uses_ = 0, computed_ = 0;
};

/// `crop` expanded outward to multiples of `grid` px and clipped to `bounds`.
cv::Rect align_to_grid(const cv::Rect& crop, int grid, const cv::Rect& bounds);

}  // namespace antpose::registration
