// Pinhole camera with OpenCV's 5-coefficient radial/tangential distortion, in the camera frame
// of the conventions (x right, y down, z along the optical axis) and OpenCV pixel coordinates
// (origin at the centre of the top-left pixel, u right, v down).
//
// Projection of a point X_camera = (X, Y, Z), Z > 0 (OpenCV's calib3d model, Brown–Conrady):
//   x = X/Z, y = Y/Z, r² = x² + y²
//   x' = x (1 + k1 r² + k2 r⁴ + k3 r⁶) + 2 p1 x y + p2 (r² + 2x²)
//   y' = y (1 + k1 r² + k2 r⁴ + k3 r⁶) + p1 (r² + 2y²) + 2 p2 x y
//   u = fx x' + cx, v = fy y' + cy
// The camera–IMU rotation R_device_camera (device = Android sensor frame) is NOT part of the
// intrinsics; see store/device_profile.hpp. For a phone's main (back) camera held in portrait,
// nominal_R_device_camera() is the layout without mounting error.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "antpose/geometry/rotation.hpp"

namespace antpose::camera {

struct CameraIntrinsics {
  int width = 0, height = 0;              // px
  double fx = 0, fy = 0, cx = 0, cy = 0;  // px
  std::array<double, 5> distortion{};     // k1, k2, p1, p2, k3 (OpenCV order)

  Mat3 K() const;
  bool has_distortion() const;
  /// Pixel of a camera-frame point (any Z > 0). std::nullopt behind the camera (Z ≤ 0).
  std::optional<Vec2> project(const Vec3& p_camera) const;
  /// The same, with the pixel's derivative by the point, d(u, v)/d(X, Y, Z), in `d_uv_d_p`
  /// (the chain of the pinhole's and the distortion's Jacobians; unchanged behind the camera).
  std::optional<Vec2> project(const Vec3& p_camera, Eigen::Matrix<double, 2, 3>& d_uv_d_p) const;
  /// Normalised distorted coordinates (x', y') of the undistorted (x, y) = (X/Z, Y/Z).
  Vec2 distort(const Vec2& xy) const;
  /// Inverse of distort by fixed-point iteration (as cv::undistortPoints); accurate to 1e-10
  /// inside the image for ordinary phone lenses.
  Vec2 undistort(const Vec2& xy_distorted) const;
  /// Unit ray (camera frame) through pixel (u, v).
  Vec3 ray(const Vec2& uv) const;
  /// "invalid: ..." reasons (non-positive size or focal length, principal point outside the
  /// image, non-finite values); empty when usable.
  std::optional<std::string> invalid_reason() const;
};

/// The intrinsics of photos `width` × `height` px taken by the same sensor at another resolution:
/// the calibrated `intrinsics` scaled by w/W and h/H (pixel centres at (i + ½)·scale − ½), the
/// distortion unchanged (it acts on normalised coordinates). A phone reading its sensor at a lower
/// resolution bins or resizes the whole frame, which is exactly this; a crop (16:9 video from a
/// 4:3 sensor) is not, so the two scales must agree to within the rounding of each side to
/// whole pixels. nullopt when they do not (another aspect ratio, a crop, or a rotated photo).
std::optional<CameraIntrinsics> rescaled_intrinsics(const CameraIntrinsics& intrinsics, int width, int height);

/// R_device_camera of a main camera on the back of the phone (Android device frame, camera frame
/// of the conventions): camera x = device x, camera y = −device y, camera z = −device z.
Mat3 nominal_R_device_camera();

}  // namespace antpose::camera
