// The camera model's projection derivative, and the model at another resolution of the same sensor
// (rescaled_intrinsics).
#include <gtest/gtest.h>

#include "antpose/camera/camera_model.hpp"

namespace antpose::camera {
namespace {

CameraIntrinsics twelve_megapixels() {
  return {4000, 3000, 3251.0, 3253.5, 2003.2, 1497.9, {0.10, -0.25, 4e-4, -3e-4, 0.12}};
}

TEST(CameraIntrinsics, TheProjectionsDerivativeMatchesItsDifferences) {
  // Strong distortion and points towards the corners, where its terms matter most.
  const CameraIntrinsics K = twelve_megapixels();
  for (const Vec3& p : {Vec3(0.3, -0.2, 4.0), Vec3(-2.0, 1.4, 3.0), Vec3(2.1, 1.5, 3.5), Vec3(0.0, 0.0, 10.0)}) {
    Eigen::Matrix<double, 2, 3> J;
    const auto uv = K.project(p, J);
    ASSERT_TRUE(uv);
    EXPECT_EQ(*uv, *K.project(p));
    for (int a = 0; a < 3; ++a) {
      const double h = 1e-5 * p.z();
      const Vec3 dp = h * Vec3::Unit(a);
      const Vec2 numeric = (*K.project(p + dp) - *K.project(p - dp)) / (2 * h);
      EXPECT_NEAR((J.col(a) - numeric).norm(), 0.0, 1e-5 * J.norm()) << "column " << a << " at " << p.transpose();
    }
  }
  Eigen::Matrix<double, 2, 3> J;
  EXPECT_FALSE(K.project(Vec3(0.1, 0.1, -1.0), J));
}

TEST(RescaledIntrinsics, APointLandsWhereTheResizedPhotoShowsIt) {
  const CameraIntrinsics native = twelve_megapixels();
  const auto small = rescaled_intrinsics(native, 1600, 1200);
  ASSERT_TRUE(small);
  EXPECT_EQ(small->width, 1600);
  EXPECT_EQ(small->height, 1200);
  EXPECT_EQ(small->distortion, native.distortion);
  // A resize maps pixel-centre coordinates u → (u + ½)·s − ½ (cv::resize's convention).
  for (const Vec3& p : {Vec3(0.3, -0.2, 4.0), Vec3(-1.1, 0.9, 3.0), Vec3(0.0, 0.0, 10.0)}) {
    const Vec2 big = *native.project(p), little = *small->project(p);
    EXPECT_NEAR(little.x(), (big.x() + 0.5) * 0.4 - 0.5, 1e-9);
    EXPECT_NEAR(little.y(), (big.y() + 0.5) * 0.4 - 0.5, 1e-9);
  }
}

TEST(RescaledIntrinsics, AcceptsTheRoundingOfTheNewSizeOnly) {
  const CameraIntrinsics native = twelve_megapixels();
  // 0.41 × 3000 = 1230; 1641 px wide is the rounding of 0.41 × 4000 = 1640 by one pixel.
  EXPECT_TRUE(rescaled_intrinsics(native, 1641, 1230));
  EXPECT_FALSE(rescaled_intrinsics(native, 1920, 1080)) << "a 16:9 crop of a 4:3 sensor";
  EXPECT_FALSE(rescaled_intrinsics(native, 3000, 4000)) << "a portrait photo for landscape intrinsics";
  EXPECT_FALSE(rescaled_intrinsics(native, 0, 1200));
}

}  // namespace
}  // namespace antpose::camera
