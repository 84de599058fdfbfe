#include "antpose/model/mesh.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>

#include <fmt/format.h>

#include "antpose/core/error.hpp"
#include "support/test_support.hpp"

namespace antpose::model {
namespace {
namespace fs = std::filesystem;
using ::testing::HasSubstr;

// A cube of side `s` centred at the origin, outward winding, as an OBJ with quads.
std::string cube_obj(double s) {
  const double h = s / 2;
  std::string out = "# cube\n";
  for (int k = 0; k < 8; ++k) out += fmt::format("v {} {} {}\n", (k & 1) ? h : -h, (k & 2) ? h : -h, (k & 4) ? h : -h);
  // Faces as quads, counter-clockwise seen from outside.
  out += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  return out;
}

// Raw bytes of a value in the requested byte order, for hand-made binary PLY files.
template <class T>
void put(std::ofstream& out, T value, bool big_endian) {
  char b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));
  if (big_endian != (std::endian::native == std::endian::big)) std::reverse(b, b + sizeof(T));
  out.write(b, sizeof(T));
}

TEST(MeshObj, ReadsIndexFormsAndFanTriangulatesQuads) {
  const Mesh m = parse_obj(
      "o thing\nmtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 1.0\nvt 0 0\nvn 0 0 1\ng side\nusemtl red\ns off\n"
      "f 1/1/1 2/1/1 3/1/1 4/1/1\nf 1//1 3//1 4//1\nf 2/1 3/1 4/1\nl 1 2\n",
      "t.obj");
  ASSERT_EQ(m.vertices.size(), 4u);
  EXPECT_EQ(m.vertices[3], Vec3(0, 1, 0));
  ASSERT_EQ(m.triangles.size(), 4u);
  EXPECT_EQ(m.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(m.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(m.triangles[2], (std::array<std::uint32_t, 3>{0, 2, 3}));
  EXPECT_EQ(m.triangles[3], (std::array<std::uint32_t, 3>{1, 2, 3}));
}

TEST(MeshObj, NegativeIndicesCountBackFromTheLatestVertex) {
  const Mesh m = parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nf -4/1 -1 -2\n", "t.obj");
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[0], (std::array<std::uint32_t, 3>{0, 1, 2}));
  EXPECT_EQ(m.triangles[1], (std::array<std::uint32_t, 3>{0, 3, 2}));
}

TEST(MeshObj, MalformedInputNamesFileAndLine) {
  EXPECT_THAT(test::input_error([] { parse_obj("v 0 0 0\nv 1 x 0\n", "bad.obj"); }), HasSubstr("bad.obj:2: bad number 'x'"));
  EXPECT_THAT(test::input_error([] { parse_obj("v 0 0\n", "bad.obj"); }), HasSubstr("bad.obj:1: vertex has 2 coordinates"));
  EXPECT_THAT(test::input_error([] { parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n", "bad.obj"); }),
              HasSubstr("bad.obj:4: vertex index 4 out of range: 3 vertices"));
  EXPECT_THAT(test::input_error([] { parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n", "bad.obj"); }),
              HasSubstr("bad.obj:4: vertex index -4 out of range"));
  EXPECT_THAT(test::input_error([] { parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "bad.obj"); }),
              HasSubstr("bad.obj:4: vertex index 0"));
  EXPECT_THAT(test::input_error([] { parse_obj("v 0 0 0\nv 1 0 0\nf 1 2\n", "bad.obj"); }),
              HasSubstr("bad.obj:3: face with 2 vertices"));
  EXPECT_THAT(test::input_error([] { parse_obj("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 a 3\n", "bad.obj"); }),
              HasSubstr("bad.obj:4: bad vertex index 'a'"));
  EXPECT_THAT(test::input_error([] { parse_obj("# nothing\nvt 0 0\n", "empty.obj"); }), HasSubstr("empty.obj: no vertices"));
  EXPECT_THAT(test::input_error([] { parse_obj("v 0 0 nan\n", "bad.obj"); }), HasSubstr("bad.obj:1: bad number 'nan'"));
}

TEST(MeshRead, ObjCubeHasOutwardVolumeAndIsClosed) {
  test::TempDir dir;
  test::write_file(dir / "cube.OBJ", cube_obj(0.5));
  const Mesh m = read_mesh(dir / "cube.OBJ");
  EXPECT_EQ(m.vertices.size(), 8u);
  EXPECT_EQ(m.triangles.size(), 12u);
  EXPECT_NEAR(enclosed_volume(m), 0.125, 1e-15);
  EXPECT_NEAR(surface_area(m), 1.5, 1e-15);
  EXPECT_TRUE(is_closed(m));
  Mesh open = m;
  open.triangles.pop_back();
  EXPECT_FALSE(is_closed(open));
  Mesh flipped = m;
  std::swap(flipped.triangles[0][1], flipped.triangles[0][2]);
  EXPECT_FALSE(is_closed(flipped));
}

TEST(MeshPly, AsciiRoundTripIsExact) {
  test::TempDir dir;
  Mesh m = parse_obj(cube_obj(0.5), "cube.obj");
  m.vertices[0] += Vec3(1.0 / 3.0, 1e-17, -0.1);
  write_ply(m, dir / "cube.ply");
  const Mesh back = read_mesh(dir / "cube.ply");
  EXPECT_EQ(back.vertices, m.vertices);
  EXPECT_EQ(back.triangles, m.triangles);
  // Also compressed, by name.
  write_ply(m, dir / "cube.ply.gz");
  EXPECT_EQ(read_mesh(dir / "cube.ply.gz").vertices, m.vertices);
}

TEST(MeshPly, CloudWriterWritesNormalsAndReadsBackAsPoints) {
  test::TempDir dir;
  PointCloud cloud;
  cloud.points = {Vec3(0, 0, 0), Vec3(0.2, 0.1, -0.05)};
  cloud.normals = {Vec3(0, 0, 1), Vec3(1, 0, 0)};
  write_ply(cloud, dir / "c.ply");
  std::ifstream in(dir / "c.ply");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_THAT(text, HasSubstr("element vertex 2\n"));
  EXPECT_THAT(text, HasSubstr("property double nz\n"));
  EXPECT_THAT(text, HasSubstr("0.2 0.1 -0.05 1 0 0\n"));
  const Mesh back = read_mesh(dir / "c.ply");
  EXPECT_EQ(back.vertices, cloud.points);
  EXPECT_TRUE(back.triangles.empty());
}

TEST(MeshPly, AsciiSkipsOtherPropertiesAndElements) {
  const Mesh m = parse_ply(
      "ply\r\nformat ascii 1.0\r\ncomment made by hand\r\nobj_info x\r\nelement vertex 4\r\nproperty uchar red\r\n"
      "property float x\r\nproperty float y\r\nproperty float z\r\nproperty list uchar int extra\r\n"
      "element face 1\r\nproperty int flags\r\nproperty list uint8 uint32 vertex_index\r\n"
      "element edge 1\r\nproperty int vertex1\r\nproperty int vertex2\r\nend_header\r\n"
      "255 0 0 0 2 7 8\r\n1 1 0 0 0\r\n\r\n2 1 1 0 1 9\r\n3 0 1 0 0\r\n5 4 0 1 2 3\r\n0 1\r\n",
      "hand.ply");
  ASSERT_EQ(m.vertices.size(), 4u);
  EXPECT_EQ(m.vertices[2], Vec3(1, 1, 0));
  ASSERT_EQ(m.triangles.size(), 2u);
  EXPECT_EQ(m.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3}));
}

void write_binary_ply(const fs::path& file, bool big_endian) {
  std::ofstream out(file, std::ios::binary);
  out << "ply\nformat " << (big_endian ? "binary_big_endian" : "binary_little_endian") << " 1.0\n"
      << "element vertex 4\nproperty double x\nproperty uchar red\nproperty float y\nproperty float z\n"
      << "property list uchar int16 extra\n"
      << "element face 2\nproperty int flags\nproperty list int uint vertex_indices\n"
      << "element material 1\nproperty float shine\nend_header\n";
  const double xs[4] = {0.0, 0.25, 0.25, 0.0};
  const float ys[4] = {0.0f, 0.0f, 0.5f, 0.5f};
  for (int k = 0; k < 4; ++k) {
    put<double>(out, xs[k], big_endian);
    put<std::uint8_t>(out, 200, big_endian);
    put<float>(out, ys[k], big_endian);
    put<float>(out, 0.125f * static_cast<float>(k), big_endian);
    put<std::uint8_t>(out, static_cast<std::uint8_t>(k % 2), big_endian);
    if (k % 2) put<std::int16_t>(out, -3, big_endian);
  }
  put<std::int32_t>(out, 7, big_endian);
  put<std::int32_t>(out, 4, big_endian);
  for (std::uint32_t i : {0u, 1u, 2u, 3u}) put<std::uint32_t>(out, i, big_endian);
  put<std::int32_t>(out, 7, big_endian);
  put<std::int32_t>(out, 3, big_endian);
  for (std::uint32_t i : {3u, 2u, 1u}) put<std::uint32_t>(out, i, big_endian);
  put<float>(out, 0.5f, big_endian);
}

TEST(MeshPly, BinaryLittleAndBigEndian) {
  test::TempDir dir;
  for (const bool big : {false, true}) {
    const fs::path file = dir / (big ? "big.ply" : "little.ply");
    write_binary_ply(file, big);
    const Mesh m = read_mesh(file);
    ASSERT_EQ(m.vertices.size(), 4u) << big;
    EXPECT_EQ(m.vertices[2], Vec3(0.25, 0.5, 0.25)) << big;
    EXPECT_EQ(m.vertices[3], Vec3(0.0, 0.5, 0.375)) << big;
    ASSERT_EQ(m.triangles.size(), 3u) << big;
    EXPECT_EQ(m.triangles[1], (std::array<std::uint32_t, 3>{0, 2, 3})) << big;
    EXPECT_EQ(m.triangles[2], (std::array<std::uint32_t, 3>{3, 2, 1})) << big;
  }
}

TEST(MeshPly, TruncatedBinaryIsAnError) {
  test::TempDir dir;
  write_binary_ply(dir / "full.ply", false);
  std::ifstream in(dir / "full.ply", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  bytes.resize(bytes.size() - 10);  // inside the second face
  test::write_file(dir / "cut.ply", bytes);
  const std::string message = test::input_error([&] { read_mesh(dir / "cut.ply"); });
  EXPECT_THAT(message, HasSubstr("cut.ply: truncated binary data"));
  EXPECT_THAT(message, HasSubstr("'face' 2 of 2"));
}

TEST(MeshPly, PointOnlyFileIsAllowed) {
  const fs::path bunny = test::shared_path("data/pointclouds/pcl/bun0.ply");
  const Mesh m = read_mesh(bunny);
  EXPECT_EQ(m.vertices.size(), 397u);
  EXPECT_TRUE(m.triangles.empty());
  EXPECT_EQ(m.vertices[0], Vec3(0.0054215998, 0.11349, 0.040748999));
}

TEST(MeshPly, MalformedInputNamesFileAndLine) {
  const std::string head =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  EXPECT_THAT(test::input_error([&] { parse_ply(head + "0 0 0\n1 0 0\n0 1 zz\n3 0 1 2\n", "m.ply"); }),
              HasSubstr("m.ply:12: bad number 'zz'"));
  EXPECT_THAT(test::input_error([&] { parse_ply(head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n", "m.ply"); }),
              HasSubstr("m.ply:13: vertex index 3 out of range: the file has 3 vertices"));
  EXPECT_THAT(test::input_error([&] { parse_ply(head + "0 0 0\n1 0 0\n0 1 0\n3 0 1 -1\n", "m.ply"); }),
              HasSubstr("m.ply:13: vertex index -1 out of range"));
  EXPECT_THAT(test::input_error([&] { parse_ply(head + "0 0 0\n1 0 0\n0 1 0\n2 0 1\n", "m.ply"); }),
              HasSubstr("m.ply:13: face with 2 vertices"));
  EXPECT_THAT(test::input_error([&] { parse_ply(head + "0 0 0\n1 0 0\n0 1\n3 0 1 2\n", "m.ply"); }),
              HasSubstr("m.ply:12: too few values"));
  EXPECT_THAT(test::input_error([&] { parse_ply(head + "0 0 0\n1 0 0 9\n0 1 0\n3 0 1 2\n", "m.ply"); }),
              HasSubstr("m.ply:11: 4 values for a 'vertex', the header declares 3"));
  EXPECT_THAT(test::input_error([&] { parse_ply(head + "0 0 0\n1 0 0\n", "m.ply"); }),
              HasSubstr("file ends after 2 of 3 'vertex' lines"));
  EXPECT_THAT(test::input_error([] {
                parse_ply(
                    "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float "
                    "y\nproperty float z\nend_header\n",
                    "m.ply");
              }),
              HasSubstr("m.ply: no vertices"));
  EXPECT_THAT(test::input_error([] { parse_ply("ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n", "m.ply"); }),
              HasSubstr("no end_header"));
  EXPECT_THAT(test::input_error([] { parse_ply("solid x\n", "m.ply"); }), HasSubstr("m.ply:1: not a PLY file"));
  EXPECT_THAT(test::input_error([] { parse_ply("ply\nformat binary_middle_endian 1.0\nend_header\n", "m.ply"); }),
              HasSubstr("m.ply:2: unknown PLY format 'binary_middle_endian'"));
  EXPECT_THAT(test::input_error([] { parse_ply("ply\nformat ascii 1.0\nelement vertex 1\nproperty float128 x\n", "m.ply"); }),
              HasSubstr("m.ply:4: unknown property type 'float128'"));
  EXPECT_THAT(test::input_error([] {
                parse_ply(
                    "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float "
                    "y\nend_header\n0 0\n",
                    "m.ply");
              }),
              HasSubstr("m.ply:3: vertex element lacks an x, y or z property"));
}

TEST(MeshRead, UnknownFormatAndMissingFile) {
  test::TempDir dir;
  test::write_file(dir / "model.stl", "solid x\n");
  EXPECT_THAT(test::input_error([&] { read_mesh(dir / "model.stl"); }),
              HasSubstr("model.stl: unknown mesh format '.stl', expected a .obj or .ply file"));
  EXPECT_THAT(test::input_error([&] { read_mesh(dir / "absent.obj"); }), HasSubstr("absent.obj: file not found"));
}

TEST(MeshUnits, MillimetresReadAsMetresAreRefusedWithTheFix) {
  test::TempDir dir;
  test::write_file(dir / "panel.obj", cube_obj(1310));
  const std::string message = test::input_error([&] { read_mesh(dir / "panel.obj"); });
  EXPECT_THAT(message, HasSubstr("panel.obj: the model is 1310 m long"));
  EXPECT_THAT(message, HasSubstr("almost surely in millimetres"));
  EXPECT_THAT(message, HasSubstr("--model-units mm"));
  const Mesh m = read_mesh(dir / "panel.obj", Units::kMillimetres);
  EXPECT_NEAR(m.vertices[7].x(), 0.655, 1e-15);
}

TEST(MeshUnits, TooSmallModelsAreRefused) {
  test::TempDir dir;
  test::write_file(dir / "metres.obj", cube_obj(1.31));
  EXPECT_THAT(test::input_error([&] { read_mesh(dir / "metres.obj", Units::kMillimetres); }),
              HasSubstr("only 0.00131 m long (largest side of its bounding box) when read as millimetres, less than "
                        "0.05 m: the file is probably in metres; drop --model-units mm"));
  test::write_file(dir / "tiny.obj", cube_obj(0.01));
  EXPECT_THAT(test::input_error([&] { read_mesh(dir / "tiny.obj"); }),
              HasSubstr("tiny.obj: the model is only 0.01 m long (largest side of its bounding box) when read as "
                        "metres, less than 0.05 m"));
}

TEST(MeshMeasures, TransformedAndBoundingBox) {
  const Mesh m = parse_obj(cube_obj(0.5), "cube.obj");
  Iso3 T = Iso3::Identity();
  T.linear() = exp_so3(Vec3(0.1, 0.2, -0.3));
  T.translation() = Vec3(1, 2, 3);
  const Mesh moved = transformed(m, T);
  EXPECT_NEAR(enclosed_volume(moved), 0.125, 1e-12);
  EXPECT_TRUE((moved.vertices[5] - T * m.vertices[5]).norm() < 1e-15);
  const auto [lo, hi] = bounding_box(m);
  EXPECT_EQ(lo, Vec3::Constant(-0.25));
  EXPECT_EQ(hi, Vec3::Constant(0.25));
  EXPECT_EQ(triangle_normal(m, 0), -Vec3::UnitZ());
}

}  // namespace
}  // namespace antpose::model
