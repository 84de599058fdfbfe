#include "antpose/registration/axis_slide.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "antpose/model/box_file.hpp"
#include "registration/panel_scene.hpp"

namespace antpose::registration {
namespace {

using fixture::make_scene;
using fixture::SyntheticScene;

const SyntheticScene& scene() {
  static const SyntheticScene s = make_scene();
  return s;
}

// The outline of the scene's panel's box (its brackets not measured), as the registration's.
SilhouetteOptions box_outline() {
  SilhouetteOptions o;
  o.outline_box_m = model::outline_box(model::parametric_panel(fixture::SceneSpec{}.panel));
  return o;
}

// How far `T` stands from the truth along the truth's long axis (m).
double along_axis(const Iso3& T, const Iso3& truth) {
  return (T.translation() - truth.translation()).dot(truth.linear().col(2));
}

TEST(AxisSlide, APoseOffAlongItsLongAxisSlidesBack) {
  const auto& s = scene();
  AxisSlideOptions o;
  for (const double off : {-0.1, 0.075}) {
    Iso3 start = s.T_board_antenna;
    start.translation() += off * s.T_board_antenna.linear().col(2);
    const auto slid = slide_along_axis(s.mesh_antenna, start, s.views, s.intrinsics, box_outline(), o);
    ASSERT_TRUE(slid) << "offset " << off;
    EXPECT_LE(std::abs(along_axis(*slid, s.T_board_antenna)), o.step_m / 2 + 1e-9) << "offset " << off;
    EXPECT_TRUE(slid->linear().isApprox(start.linear())) << "the slide keeps the orientation";
  }
}

TEST(AxisSlide, ThePoseWhereTheOutlineFitsStays) {
  const auto& s = scene();
  EXPECT_FALSE(slide_along_axis(s.mesh_antenna, s.T_board_antenna, s.views, s.intrinsics, box_outline(), {}));
}

TEST(AxisSlide, RejectsBadOptions) {
  const auto& s = scene();
  AxisSlideOptions o;
  o.reach_m = 0.01;  // less than a step
  EXPECT_THROW(slide_along_axis(s.mesh_antenna, s.T_board_antenna, s.views, s.intrinsics, box_outline(), o),
               std::invalid_argument);
}

}  // namespace
}  // namespace antpose::registration
