// The model-free face fit and the ROI argument of antpose measure.
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "antpose/geometry/attitude.hpp"
#include "antpose/measure/model_free.hpp"
#include "antpose/measure/non_contact.hpp"
#include "antpose/model/antenna_model.hpp"
#include "antpose/model/sampling.hpp"
#include "support/test_support.hpp"

namespace antpose::measure {
namespace {

using ::testing::HasSubstr;

// A panel's surface as three cameras in front of it see it, in a scene frame where the panel
// has attitude R_scene_antenna, with Gaussian noise.
struct Scan {
  PointCloud cloud;
  std::vector<Vec3> viewpoints;
};

Scan panel_scan(const Mat3& R_scene_antenna, double noise_m, std::uint64_t seed) {
  const auto panel = model::parametric_panel({});
  Scan s;
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, noise_m);
  for (const double side : {-2.0, 0.0, 2.0}) {
    const Vec3 eye_antenna(side, 8.0, -1.0);
    const auto seen = model::visible_surface(panel.mesh_antenna, eye_antenna, 0.01, seed);
    for (const auto& p : seen.points) s.cloud.points.push_back(R_scene_antenna * p + Vec3(n(rng), n(rng), n(rng)));
    s.viewpoints.push_back(R_scene_antenna * eye_antenna);
  }
  return s;
}

TEST(ModelFree, RecoversTheFrontFaceAndLongAxis) {
  for (const auto& [az, tilt, roll] : {std::tuple{30.0, 4.0, 0.5}, {200.0, 10.0, -1.5}, {315.0, 0.0, 0.0}}) {
    const Mat3 R = rotation_from_attitude(deg2rad(az), deg2rad(tilt), deg2rad(roll));
    const Scan scan = panel_scan(R, 0.002, 7);
    const FaceFit fit = fit_front_face(scan.cloud, scan.viewpoints, Vec3::UnitZ(), {});
    const auto got = attitude_from_rotation(fit.R_scene_antenna);
    EXPECT_NEAR(rad2deg(wrap_pi(*got.azimuth - deg2rad(az))), 0.0, 0.2) << az;
    EXPECT_NEAR(rad2deg(got.downtilt), tilt, 0.2) << az;
    // The long axis comes from where the face ends: coarser, as its covariance says.
    EXPECT_NEAR(rad2deg(*got.roll), roll, 1.0) << az;
    EXPECT_LT(fit.rmse_m, 0.004);
    EXPECT_NEAR(fit.length_m, 1.31 * 0.9, 0.1);
    const double roll_sigma = std::sqrt(fit.covariance.diagonal().maxCoeff());
    EXPECT_GT(roll_sigma, deg2rad(0.1));
    EXPECT_LT(roll_sigma, deg2rad(2.0));
    EXPECT_THAT(fit.warnings.front(), HasSubstr("taken to be the radome"));
  }
}

TEST(ModelFree, RefusesWhatIsNotAnElongatedFace) {
  PointCloud blob;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 0.3);
  for (int i = 0; i < 2000; ++i) blob.points.emplace_back(n(rng), n(rng), n(rng));
  try {
    fit_front_face(blob, {Vec3(0, -5, 0)}, Vec3::UnitZ(), {});
    FAIL() << "a blob has no face";
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("no flat face"));
  }
  PointCloud square;
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 40; ++j) square.points.emplace_back(0.01 * i, 0.0, 0.01 * j);
  try {
    fit_front_face(square, {Vec3(0, -5, 0)}, Vec3::UnitZ(), {});
    FAIL() << "a square has no long axis";
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("not elongated enough"));
  }
  try {
    fit_front_face(PointCloud{}, {}, Vec3::UnitZ(), {});
    FAIL();
  } catch (const MeasurementError& e) {
    EXPECT_THAT(e.what(), HasSubstr("0 points"));
  }
}

TEST(MeasureRoi, ParsesAndNamesBadValues) {
  const AntennaRoi r = parse_roi("images/img_003.jpg:120,30,400,1500");
  EXPECT_EQ(r.image, "images/img_003.jpg");
  EXPECT_EQ(r.roi.x, 120);
  EXPECT_EQ(r.roi.y, 30);
  EXPECT_EQ(r.roi.width, 400);
  EXPECT_EQ(r.roi.height, 1500);
  EXPECT_THAT(test::input_error([] { parse_roi("img.jpg:1,2,3"); }), HasSubstr("is not IMAGE:x,y,w,h"));
  EXPECT_THAT(test::input_error([] { parse_roi("1,2,3,4"); }), HasSubstr("is not IMAGE:x,y,w,h"));
  // A number beyond int is refused, not wrapped into another rectangle.
  EXPECT_THAT(test::input_error([] { parse_roi("img.jpg:4294968763,2,30,40"); }),
              HasSubstr("'img.jpg:4294968763,2,30,40': 4294968763 is far beyond any photo's pixels"));
  EXPECT_THAT(test::input_error([] { parse_roi("img.jpg:1,2,30,40x"); }), HasSubstr("is not IMAGE:x,y,w,h"));
  EXPECT_THAT(test::input_error([] { parse_roi("img.jpg:1,2,30"); }), HasSubstr("is not IMAGE:x,y,w,h"));
  EXPECT_THAT(test::input_error([] { parse_roi("img.jpg:1,2,300,400x"); }), HasSubstr("is not IMAGE:x,y,w,h"));
  EXPECT_THAT(test::input_error([] { parse_roi("img.jpg:-1,2,300,400"); }), HasSubstr("at least 8 px"));
  EXPECT_THAT(test::input_error([] { parse_roi("img.jpg:1,2,3,400"); }), HasSubstr("at least 8 px"));
}

}  // namespace
}  // namespace antpose::measure
