#include "antpose/model/antenna_model.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <numbers>
#include <stdexcept>

#include "antpose/core/error.hpp"
#include "antpose/model/sampling.hpp"
#include "support/test_support.hpp"

namespace antpose::model {
namespace {
using ::testing::HasSubstr;

Iso3 known_pose() {
  Iso3 T_mesh_antenna = Iso3::Identity();
  T_mesh_antenna.linear() = exp_so3(Vec3(-0.4, 0.9, 2.6));
  T_mesh_antenna.translation() = Vec3(-0.3, 2.0, 1.1);
  return T_mesh_antenna;
}

double expected_volume(const PanelSpec& s) {
  const double r = s.edge_radius_m;
  double v = s.width_m * s.depth_m * s.height_m - (4 - std::numbers::pi) * r * r * s.height_m;
  if (s.bracket) v += 2 * s.bracket_width_m * s.bracket_depth_m * s.bracket_height_m;
  return v;
}

std::vector<PanelSpec> some_specs() {
  std::vector<PanelSpec> specs(4);
  specs[1].bracket = false;
  specs[2].edge_radius_m = 0;
  specs[3].width_m = 0.159, specs[3].depth_m = 0.08, specs[3].arc_segments = 12;
  return specs;
}

TEST(Panel, IsClosedWithTheExpectedVolume) {
  for (const PanelSpec& s : some_specs()) {
    const AntennaModel m = parametric_panel(s);
    EXPECT_TRUE(is_closed(m.mesh_antenna)) << m.name;
    // Positive: wound outwards. The arcs are inscribed polygons, a little less than the formula.
    EXPECT_NEAR(enclosed_volume(m.mesh_antenna) / expected_volume(s), 1.0, 0.005) << m.name;
  }
}

TEST(Panel, SizeAndExtent) {
  PanelSpec s;
  const AntennaModel m = parametric_panel(s);
  EXPECT_EQ(m.size_m, Vec3(0.30, 0.16, 1.31));
  EXPECT_EQ(m.name, "parametric-1310x300x160");
  EXPECT_TRUE(m.T_antenna_mesh.matrix().isIdentity());
  const auto [lo, hi] = bounding_box(m.mesh_antenna);
  EXPECT_LT((lo - Vec3(-0.15, -0.08 - s.bracket_depth_m, -0.655)).norm(), 1e-12);
  EXPECT_LT((hi - Vec3(0.15, 0.08, 0.655)).norm(), 1e-12);
}

TEST(Panel, NormalsPointOutwards) {
  const PanelSpec s;
  const AntennaModel m = parametric_panel(s);
  const PointCloud cloud = sample_surface(m.mesh_antenna, 0.01, 7);
  std::size_t body = 0, bracket = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.points[i];
    const Vec3& n = cloud.normals[i];
    if (p.y() >= -s.depth_m / 2 - 1e-12) {  // the panel's convex body: away from its centre
      ++body;
      ASSERT_GT(p.dot(n), 0) << p.transpose() << " n " << n.transpose();
    } else {  // a bracket: away from the bracket's centre
      ++bracket;
      const Vec3 centre(0, -s.depth_m / 2 - s.bracket_depth_m / 2, p.z() > 0 ? s.height_m / 4 : -s.height_m / 4);
      ASSERT_GT((p - centre).dot(n), 0) << p.transpose() << " n " << n.transpose();
    }
  }
  EXPECT_GT(body, 10000u);
  EXPECT_GT(bracket, 300u);
}

TEST(Panel, InvalidSpecsAreRefused) {
  const auto refusal = [](auto change) -> std::string {
    PanelSpec s;
    change(s);
    try {
      parametric_panel(s);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    ADD_FAILURE() << "no std::invalid_argument thrown";
    return "";
  };
  EXPECT_THAT(refusal([](PanelSpec& s) { s.width_m = 0; }), HasSubstr("panel size 0 x 0.16 x 1.31 m"));
  EXPECT_THAT(refusal([](PanelSpec& s) { s.height_m = -1; }), HasSubstr("all must be > 0"));
  EXPECT_THAT(
      refusal([](PanelSpec& s) { s.edge_radius_m = 0.08; }),
      HasSubstr("panel edge radius 0.08 m: must be ≥ 0 and below half the smaller of width and depth (0.08 m)"));
  EXPECT_THAT(refusal([](PanelSpec& s) { s.edge_radius_m = -0.01; }), HasSubstr("panel edge radius -0.01 m"));
  EXPECT_THAT(refusal([](PanelSpec& s) { s.arc_segments = 0; }), HasSubstr("arc_segments = 0"));
  EXPECT_THAT(refusal([](PanelSpec& s) { s.bracket_width_m = 0.26; }),
              HasSubstr("bracket width 0.26 m: must be below the flat part of the back plate"));
  EXPECT_THAT(refusal([](PanelSpec& s) { s.bracket_height_m = 0.7; }),
              HasSubstr("bracket height 0.7 m: must be below 0.655 m"));
  // Brackets 0.1 of the height from the ends: at most 0.262 m tall, or they overhang the ends.
  EXPECT_THAT(refusal([](PanelSpec& s) { s.bracket_end_fraction = 0.1, s.bracket_height_m = 0.3; }),
              HasSubstr("bracket height 0.3 m: must be below 0.262 m"));
  EXPECT_THAT(refusal([](PanelSpec& s) { s.bracket_end_fraction = 0.5; }), HasSubstr("bracket end fraction 0.5"));
  EXPECT_THAT(refusal([](PanelSpec& s) { s.bracket_depth_m = 0; }), HasSubstr("panel bracket size"));
  EXPECT_THAT(refusal([](PanelSpec& s) { s.end_cap_height_m = 0.7; }),
              HasSubstr("panel end caps 0.7 m long with a rim of 0 m: the length must be ≥ 0 and below half the "
                        "height (0.655 m)"));
  EXPECT_THAT(refusal([](PanelSpec& s) { s.end_cap_height_m = 0.04, s.end_cap_rim_m = -0.001; }),
              HasSubstr("a rim of -0.001 m"));
  PanelSpec no_bracket;
  no_bracket.bracket = false, no_bracket.bracket_width_m = 5;  // ignored without brackets
  EXPECT_NO_THROW(parametric_panel(no_bracket));
}

// End caps 4 cm long standing 8 mm out of the radome: closed meshes of their own at each end, in
// the panel's mesh, outside its box across but not along; flush caps change nothing.
TEST(Panel, EndCapsStandOutOfTheRadome) {
  PanelSpec s;
  s.end_cap_height_m = 0.04, s.end_cap_rim_m = 0.008;
  const auto caps = end_cap_meshes(s);
  ASSERT_EQ(caps.size(), 2u);
  for (const auto& cap : caps) EXPECT_TRUE(is_closed(cap));
  const auto [lo, hi] = bounding_box(caps[1]);
  EXPECT_NEAR(hi.z(), s.height_m / 2, 1e-12);
  EXPECT_NEAR(lo.z(), s.height_m / 2 - 0.04, 1e-12);
  EXPECT_NEAR(hi.x(), s.width_m / 2 + 0.008, 1e-12);
  EXPECT_NEAR(lo.y(), -s.depth_m / 2 - 0.008, 1e-12);

  const auto capped = parametric_panel(s);
  EXPECT_EQ(capped.size_m, Vec3(s.width_m, s.depth_m, s.height_m)) << "the box is the radome's";
  EXPECT_TRUE(outline_box(capped).isApprox(capped.size_m + Vec3(0.016, 0.016, 0.0)));
  const auto plain = parametric_panel(PanelSpec{});
  EXPECT_EQ(capped.mesh_antenna.triangles.size(),
            plain.mesh_antenna.triangles.size() + caps[0].triangles.size() + caps[1].triangles.size());
  EXPECT_NEAR(bounding_box(capped.mesh_antenna).second.x(), s.width_m / 2 + 0.008, 1e-12);

  s.end_cap_rim_m = 0;
  EXPECT_EQ(parametric_panel(s).mesh_antenna.triangles.size(), plain.mesh_antenna.triangles.size());
  EXPECT_EQ(outline_box(parametric_panel(s)), plain.size_m);
  EXPECT_TRUE(end_cap_meshes(PanelSpec{}).empty());
}

TEST(Panel, BuiltinsByName) {
  for (const auto& name : builtin_panel_names()) {
    const AntennaModel m = builtin_panel(name);
    EXPECT_EQ(m.name, name);
    EXPECT_TRUE(is_closed(m.mesh_antenna)) << name;
  }
  EXPECT_EQ(builtin_panel("thesis-1310x159x80").size_m, Vec3(0.159, 0.080, 1.31));
  EXPECT_EQ(builtin_panel("panel-1310x300x160").size_m, Vec3(0.30, 0.16, 1.31));
  EXPECT_EQ(builtin_panel("panel-2000x300x150").size_m, Vec3(0.30, 0.15, 2.0));
  const std::string message = test::input_error([] { builtin_panel("yagi"); });
  EXPECT_THAT(message, HasSubstr("unknown built-in antenna model 'yagi': expected panel-<h>x<w>x<d>"));
  EXPECT_THAT(message, HasSubstr("panel-1310x300x160, thesis-1310x159x80, panel-2000x300x150"));
}

TEST(Panel, AnyDatasheetBoxByName) {
  const AntennaModel m = builtin_panel("panel-1850x280x120");
  EXPECT_EQ(m.name, "panel-1850x280x120");
  EXPECT_EQ(m.size_m, Vec3(0.28, 0.12, 1.85));
  EXPECT_TRUE(is_closed(m.mesh_antenna));
  EXPECT_TRUE(is_builtin_panel("panel-1850x280x120"));
  // The named ones are the same panels as before.
  const auto [lo, hi] = bounding_box(builtin_panel("panel-2000x300x150").mesh_antenna);
  EXPECT_LT((lo - Vec3(-0.15, -0.075 - 0.06, -1.0)).norm(), 1e-12);
  EXPECT_LT((hi - Vec3(0.15, 0.075, 1.0)).norm(), 1e-12);
  // The extremes of the ranges; the narrowest panel's brackets narrowed to fit its back plate.
  EXPECT_EQ(builtin_panel("panel-300x100x50").size_m, Vec3(0.1, 0.05, 0.3));
  EXPECT_EQ(builtin_panel("panel-4000x800x400").size_m, Vec3(0.8, 0.4, 4.0));
  for (const char* bad : {"panel-299x300x160", "panel-1310x90x60", "panel-1310x300x40", "panel-1310x300x401",
                          "panel-1310x200x250", "panel-4001x300x160", "panel-1310x300", "panel-1310x300x160x1",
                          "panel-1310.5x300x160", "panel-01310x300x160", "panel-x300x160", "panel-1310X300X160",
                          "thesis-1310x160x80"}) {
    EXPECT_FALSE(is_builtin_panel(bad)) << bad;
    const std::string message = test::input_error([&] { builtin_panel(bad); });
    EXPECT_THAT(message, HasSubstr("h 300..4000, w 100..800, d 50..400, d <= w")) << bad;
  }
}

TEST(AntennaModel, LoadsAMeshPlacedByItsBoxFile) {
  test::TempDir dir;
  const AntennaModel panel = parametric_panel(PanelSpec{});
  write_ply(transformed(panel.mesh_antenna, known_pose()), dir / "scan.ply");
  test::write_file(dir / "scan.box", format_box_file(box_corners(panel.size_m, known_pose())));
  const AntennaModel m = load_antenna_model(dir / "scan.ply", dir / "scan.box");
  EXPECT_EQ(m.name, "scan");
  EXPECT_LT((m.size_m - panel.size_m).norm(), 1e-9);
  EXPECT_LT((m.T_antenna_mesh.matrix() - known_pose().inverse().matrix()).cwiseAbs().maxCoeff(), 1e-9);
  ASSERT_EQ(m.mesh_antenna.vertices.size(), panel.mesh_antenna.vertices.size());
  for (std::size_t i = 0; i < m.mesh_antenna.vertices.size(); ++i)
    ASSERT_LT((m.mesh_antenna.vertices[i] - panel.mesh_antenna.vertices[i]).norm(), 1e-9) << i;
}

TEST(AntennaModel, LoadsMillimetreFiles) {
  test::TempDir dir;
  const AntennaModel panel = parametric_panel(PanelSpec{});
  Iso3 to_mm = known_pose();
  to_mm.linear() *= 1000, to_mm.translation() *= 1000;  // a similarity, fine for writing files
  write_ply(transformed(panel.mesh_antenna, Iso3(to_mm)), dir / "scan.obj.ply");
  auto corners = box_corners(panel.size_m, known_pose());
  for (auto& c : corners) c *= 1000;
  test::write_file(dir / "scan.box", format_box_file(corners));
  EXPECT_THAT(test::input_error([&] { load_antenna_model(dir / "scan.obj.ply", dir / "scan.box"); }),
              HasSubstr("--model-units mm"));
  const AntennaModel m = load_antenna_model(dir / "scan.obj.ply", dir / "scan.box", Units::kMillimetres);
  EXPECT_LT((m.size_m - panel.size_m).norm(), 1e-9);
  EXPECT_LT((m.mesh_antenna.vertices[5] - panel.mesh_antenna.vertices[5]).norm(), 1e-9);
}

TEST(AntennaModel, BoxInOtherUnitsOrPlaceIsRefused) {
  test::TempDir dir;
  const AntennaModel panel = parametric_panel(PanelSpec{});
  write_ply(transformed(panel.mesh_antenna, known_pose()), dir / "scan.ply");
  auto corners = box_corners(panel.size_m, known_pose());
  for (auto& c : corners) c *= 1000;
  test::write_file(dir / "mm.box", format_box_file(corners));
  EXPECT_THAT(test::input_error([&] { load_antenna_model(dir / "scan.ply", dir / "mm.box"); }),
              HasSubstr("mm.box: the box does not fit the mesh"));
  corners = box_corners(panel.size_m);  // the antenna frame, not the file's coordinates
  test::write_file(dir / "other.box", format_box_file(corners));
  EXPECT_THAT(test::input_error([&] { load_antenna_model(dir / "scan.ply", dir / "other.box"); }),
              HasSubstr("must be in the mesh's coordinates and units"));
}

TEST(AntennaModel, WithoutBoxFileTheFrameIsNotGuessed) {
  test::TempDir dir;
  PanelSpec s;
  s.bracket = false;
  const AntennaModel panel = parametric_panel(s);
  write_ply(transformed(panel.mesh_antenna, known_pose()), dir / "scan.ply");
  const std::string message = test::input_error([&] { load_antenna_model(dir / "scan.ply", std::nullopt); });
  EXPECT_THAT(message, HasSubstr("scan.ply: a box file is needed to place this mesh in the antenna frame"));
  EXPECT_THAT(message, HasSubstr("about 0.300 x 0.160 x 1.310 m, longest last"));
  EXPECT_THAT(message, HasSubstr("or declare the mesh canonical"));
}

TEST(AntennaModel, CanonicalMeshIsOnlyCentred) {
  test::TempDir dir;
  const AntennaModel panel = parametric_panel(PanelSpec{});
  const Iso3 shift(Eigen::Translation3d(1.0, -2.0, 3.0));
  write_ply(transformed(panel.mesh_antenna, shift), dir / "canonical.ply");
  const AntennaModel m = load_antenna_model(dir / "canonical.ply", std::nullopt, Units::kMetres, true);
  const auto [lo, hi] = bounding_box(m.mesh_antenna);
  EXPECT_LT(((lo + hi) / 2).norm(), 1e-12);
  EXPECT_TRUE(m.T_antenna_mesh.linear().isIdentity());
  // The bracket sticks out at the back, so the bounding box is deeper than the panel's box.
  EXPECT_LT((m.size_m - Vec3(0.30, 0.16 + PanelSpec{}.bracket_depth_m, 1.31)).norm(), 1e-12);
}

TEST(AntennaModel, PointCloudIsNotAModel) {
  test::TempDir dir;
  PointCloud cloud;
  cloud.points = {Vec3(0, 0, 0), Vec3(0.3, 0, 0), Vec3(0, 0, 1.3)};
  write_ply(cloud, dir / "points.ply");
  EXPECT_THAT(test::input_error([&] { load_antenna_model(dir / "points.ply", std::nullopt, Units::kMetres, true); }),
              HasSubstr("points.ply: the mesh has no faces"));
  // Faces whose corners lie on a line: triangles, but no surface.
  test::write_file(dir / "flat.obj", "v 0 0 0\nv 0.5 0 0\nv 1.3 0 0\nf 1 2 3\nf 3 2 1\n");
  EXPECT_THAT(test::input_error([&] { load_antenna_model(dir / "flat.obj", std::nullopt, Units::kMetres, true); }),
              HasSubstr("flat.obj: the mesh's 2 faces have no area"));
}

TEST(AntennaModel, PrincipalAxesFindTheLongAxisUpToSign) {
  PanelSpec s;
  s.bracket = false;
  const Mesh mesh = transformed(parametric_panel(s).mesh_antenna, known_pose());
  const AntennaBox box = principal_axes_box(mesh);
  EXPECT_LT((box.size_m - Vec3(0.30, 0.16, 1.31)).norm(), 1e-9);
  const Mat3 R_pca_antenna = box.T_antenna_mesh.linear() * known_pose().linear();
  // Each principal axis is an antenna axis, with either sign.
  EXPECT_LT((R_pca_antenna.cwiseAbs() - Mat3::Identity()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(R_pca_antenna.determinant(), 1.0, 1e-12);
  EXPECT_LT((box.T_antenna_mesh * known_pose().translation()).norm(), 1e-9);  // centre of the box
}

}  // namespace
}  // namespace antpose::model
