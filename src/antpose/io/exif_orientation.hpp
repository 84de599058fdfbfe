// EXIF Orientation (tag 0x0112, values 1–8): how a photo stored in the sensor's pixels is turned
// or mirrored to be shown upright. antpose works in the stored pixels, which the intrinsics
// describe (io/photo_file.hpp); what a person reads off a photo (a rectangle drawn round an
// antenna) is in the upright one, and what antpose shows (the report) is turned upright.
//
// The eight values (EXIF 2.32, §4.6.4 A, "Orientation"), as the stored image's row 0 and
// column 0 appear when shown: 1 top/left, 2 top/right (mirrored), 3 bottom/right (turned 180°),
// 4 bottom/left (mirrored), 5 left/top (transposed), 6 right/top (shown turned 90° clockwise),
// 7 right/bottom (transverse), 8 left/bottom (shown turned 90° counter-clockwise).
#pragma once

#include <opencv2/core.hpp>

namespace antpose::io {

/// Whether `orientation` is one of the eight EXIF values.
constexpr bool is_exif_orientation(int orientation) { return orientation >= 1 && orientation <= 8; }

/// The size of a photo stored as `stored` when shown upright (width and height swap for 5–8).
cv::Size upright_size(const cv::Size& stored, int orientation);

/// A rectangle of the upright photo (px, edges at whole pixels) in the stored photo's pixels.
cv::Rect stored_rect(const cv::Rect& upright, const cv::Size& stored, int orientation);

/// The stored image turned and mirrored as EXIF says, to be shown upright.
cv::Mat upright_image(const cv::Mat& stored, int orientation);

}  // namespace antpose::io
