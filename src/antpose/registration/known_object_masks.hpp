// The masks of one photo's known objects for the outline refinement (silhouette.hpp
// SilhouetteView: occluders filled, background edges drawn, both widened by a guard), and the
// photo's edge images zeroed under them, so that no known object's border is taken for the
// antenna's outline.
//
// A registration refines dozens of starts in the same photos with the same known objects.
// KnownObjectMasks draws each mask once per crop that the photo's edge pyramid keeps
// (edge_pyramid.hpp) and level, over that whole crop, and serves every refinement a sub-image of
// it: drawing, widening and applying a mask per refinement costs about as much as a quarter of
// the descents. A kept crop's origin lies on every level's pixel grid, so a sub-image is the mask
// drawn for the smaller crop alone, except that an object just outside that crop now reaches in
// by its guard, as it should. Thread-safe.
#pragma once

#include <cstddef>
#include <mutex>
#include <vector>

#include <opencv2/core.hpp>

#include "antpose/registration/silhouette.hpp"

namespace antpose::registration {

/// The known objects' mask of `view` over an image of `size` whose top-left corner lies at
/// `origin` (full-resolution px), at pyramid `level`: 255 within `guard_px` (the level's px) of
/// an occluder or a background edge, else 0.
cv::Mat known_object_mask(const SilhouetteView& view, const Vec2& origin, cv::Size size, int level, double guard_px);

struct MaskedEdges {
  cv::Mat mask;    // CV_8UC1, as known_object_mask
  cv::Mat gx, gy;  // the edge images, 0 under the mask (the images given where it is empty)
};

/// `gx`, `gy` zeroed under `mask`: copies, or the images themselves where the mask is empty.
MaskedEdges masked_edges(cv::Mat mask, const cv::Mat& gx, const cv::Mat& gy);

class KnownObjectMasks {
 public:
  /// `gx`, `gy`: level `level` of `view`'s edge images, sub-images of a crop the edge pyramid
  /// keeps (EdgePyramid::gradients), with their top-left corner at `origin` (full-resolution px);
  /// masked by `view`'s known objects.
  MaskedEdges masked(const SilhouetteView& view, const cv::Mat& gx, const cv::Mat& gy, const Vec2& origin, int level,
                     double guard_px);

  std::size_t drawn() const;  // masks drawn so far (for tests)

 private:
  struct Kept {
    int level = 0;
    double guard_px = 0;
    std::size_t objects = 0;  // hash of the view's known objects
    MaskedEdges whole;
    cv::Mat source_gx;  // the kept crop's gx, whose data identifies it (held, so its address is not reused)
    std::size_t last_use = 0;
  };

  mutable std::mutex mutex_;
  std::vector<Kept> kept_;
  std::size_t uses_ = 0, drawn_ = 0;
};

}  // namespace antpose::registration
