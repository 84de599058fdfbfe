// The model-free shortcut, when no antenna model is at hand: the radome is the large flat face
// the photos look at, and the panel's long edges run along its longest extent.
//   y_a = the normal of the dominant plane (RANSAC, Fischler & Bolles 1981, then a least-squares
//         refit of its inliers), turned towards the cameras;
//   z_a = the principal direction of the inliers within that plane, signed up;
//   x_a = y_a × z_a.
// It cannot tell the radome from the back plate: photographed from behind, it reports the back
// plate's normal, 180° off. Every result says so in its warnings, and warns too when the face is
// not clearly elongated or holds few of the points. Use a model when in doubt.
#pragma once

#include <cstdint>
#include <vector>

#include "antpose/core/error.hpp"
#include "antpose/geometry/point_cloud.hpp"

namespace antpose::measure {

struct ModelFreeOptions {
  double plane_threshold_m = 0.01;  // RANSAC inlier distance
  int ransac_iterations = 500;
  double min_inlier_share = 0.3;  // of the region's points
  double min_elongation = 2.0;    // long-axis spread / short-axis spread of the face
  double edge_sigma_m = 0.01;     // how well the face's ends are known (the long axis's σ)
  std::uint64_t seed = 1;
};

struct FaceFit {
  Mat3 R_scene_antenna = Mat3::Identity();  // columns x_a, y_a, z_a in the scene frame
  Vec3 centre_scene = Vec3::Zero();         // the face's centroid
  double rmse_m = 0.0;                      // inliers' distance to the plane
  double inlier_share = 0.0;
  double length_m = 0.0, width_m = 0.0;  // the face's extent along z_a and x_a (5–95 %)
  /// Of the rotation (left perturbation, scene frame, rad²): the normal's from the inliers'
  /// scatter, the long axis's from edge_sigma_m over the face's length.
  Mat3 covariance = Mat3::Zero();
  std::vector<std::string> warnings;
};

/// `cloud_scene` the region's points, `viewpoints_scene` the camera centres, `up_scene` the unit
/// up direction (all one frame). MeasurementError for fewer than 50 points, no plane holding
/// min_inlier_share of them, or a face too square to give a long axis.
FaceFit fit_front_face(const PointCloud& cloud_scene, const std::vector<Vec3>& viewpoints_scene, const Vec3& up_scene,
                       const ModelFreeOptions& options);

}  // namespace antpose::measure
