// OBJ loading (and its errors), mesh transforms, and albedo textures: sRGB
// decoding, the uv v-flip, bilinear filtering and wrap addressing.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "geometry/Mesh.h"
#include "geometry/Texture.h"
#include "geometry/Triangle.h"
#include "image/ImageIo.h"
#include "support/TestSupport.h"
#include "util/Error.h"

using namespace pyrolume;
using namespace pyrolume::geometry;

namespace {

// The message of the InputError that f throws (fails the test if none).
template <typename F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "not an InputError: " << e.what();
    return {};
  }
  ADD_FAILURE() << "no exception";
  return {};
}

}  // namespace

TEST(Obj, LoadsPositionsNormalsUvsAndTriangulates) {
  const auto dir = test::temp_dir("geometry_obj");
  const auto file = dir / "quad.obj";
  test::write_file(file,
                   "# a unit quad in the xz plane, as a polygon, and a triangle with no uvs\n"
                   "mtllib missing.mtl\n"
                   "o quad\n"
                   "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n"
                   "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                   "vn 0 2 0\n"
                   "usemtl rock\n"
                   "f 1/1/1 4/4/1 3/3/1 2/2/1\n"
                   "o tri\n"
                   "v 0 1 0\nv 1 1 0\nv 0 1 1\n"
                   "f -3 -1 -2\n");
  const Mesh m = load_obj(file);
  ASSERT_EQ(m.positions.size(), 7u);
  ASSERT_EQ(m.triangles.size(), 3u);
  ASSERT_EQ(m.normals.size(), 1u);
  EXPECT_FLOAT_EQ(m.normals[0].y, 1.0f);  // normalised on load
  ASSERT_EQ(m.uvs.size(), 4u);
  for (int t = 0; t < 2; ++t)
    for (const auto& c : m.triangles[size_t(t)]) {
      EXPECT_NE(c.normal, kNoIndex);
      EXPECT_NE(c.uv, kNoIndex);
      // Every corner's uv equals its position's xz (the file is built that way).
      EXPECT_EQ(m.uvs[c.uv], glm::vec2(m.positions[c.position].x, m.positions[c.position].z));
    }
  // Negative (relative) indices; no normals or uvs.
  EXPECT_EQ(m.triangles[2][0].position, 4u);
  EXPECT_EQ(m.triangles[2][1].position, 6u);
  EXPECT_EQ(m.triangles[2][0].uv, kNoIndex);
  EXPECT_EQ(m.triangles[2][0].normal, kNoIndex);

  const std::vector<Triangle> tris = triangles_of(m, 5, 2, 100);
  ASSERT_EQ(tris.size(), 3u);
  EXPECT_TRUE(tris[0].has_uvs && tris[0].has_normals);
  EXPECT_FALSE(tris[2].has_uvs || tris[2].has_normals);
  EXPECT_EQ(tris[1].material, 5u);
  EXPECT_EQ(tris[1].mesh, 2u);
  EXPECT_EQ(tris[1].source, 101u);
  // The quad's area is covered once: the two triangles' areas sum to 1.
  double area = 0.0;
  for (int t = 0; t < 2; ++t)
    area += 0.5 * glm::length(glm::cross(glm::dvec3(tris[size_t(t)].p[1] - tris[size_t(t)].p[0]),
                                         glm::dvec3(tris[size_t(t)].p[2] - tris[size_t(t)].p[0])));
  EXPECT_NEAR(area, 1.0, 1e-12);
  // The hit of a ray reports the interpolated uv = xz.
  SurfaceHit hit;
  const Ray ray{{0.3, 1.0 - 2.0, 0.8}, {0, 1, 0}};
  bool found = false;
  for (const Triangle& tri : tris) {
    double t, b1, b2;
    if (tri.has_uvs && intersect_triangle(TriangleRay(ray), tri, 1.5, t, b1, b2)) {
      hit.t = t;
      hit.b1 = b1;
      hit.b2 = b2;
      finish_triangle_hit(tri, ray, hit);
      found = true;
    }
  }
  ASSERT_TRUE(found);
  EXPECT_NEAR(hit.uv.x, 0.3, 1e-7);
  EXPECT_NEAR(hit.uv.y, 0.8, 1e-7);
  EXPECT_NEAR(std::fabs(hit.normal.y), 1.0, 1e-12);
  EXPECT_NEAR(hit.shading_normal.y, 1.0, 1e-12);
}

TEST(Obj, ErrorsNameTheFileAndTheReason) {
  const auto dir = test::temp_dir("geometry_obj_bad");
  const auto missing = dir / "nope.obj";
  std::string msg = input_error_of([&] { load_obj(missing); });
  EXPECT_NE(msg.find(missing.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("no such file"), std::string::npos) << msg;

  const auto garbage = dir / "garbage.obj";
  test::write_file(garbage, std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR binary junk\n", 28) + "hello world\n");
  msg = input_error_of([&] { load_obj(garbage); });
  EXPECT_NE(msg.find(garbage.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("no triangles"), std::string::npos) << msg;

  const auto range = dir / "range.obj";
  test::write_file(range, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n");
  msg = input_error_of([&] { load_obj(range); });
  EXPECT_NE(msg.find(range.string()), std::string::npos) << msg;
  EXPECT_NE(msg.find("vertex 9 of 3"), std::string::npos) << msg;

  const auto quad = dir / "quad_range.obj";
  test::write_file(quad, "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 7\n");
  msg = input_error_of([&] { load_obj(quad); });
  EXPECT_NE(msg.find(quad.string()), std::string::npos) << msg;

  msg = input_error_of([&] { load_obj(dir); });
  EXPECT_NE(msg.find("directory"), std::string::npos) << msg;
  // One line each.
  EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
}

TEST(Obj, TransformMovesPositionsAndNormals) {
  Mesh m;
  m.positions = {{1, 0, 0}};
  m.normals = {{1, 1, 0}};
  m.normals[0] = glm::normalize(m.normals[0]);
  // Scale x by 2, then translate by (0, 0, 5).
  glm::dmat4 M(1.0);
  M[0][0] = 2.0;
  M[3] = glm::dvec4(0, 0, 5, 1);
  transform_mesh(m, M);
  EXPECT_EQ(m.positions[0], glm::vec3(2, 0, 5));
  // Normals go by the inverse transpose: (1, 1, 0) → (1/2, 1, 0), normalised.
  const glm::vec3 want = glm::normalize(glm::vec3(0.5f, 1.0f, 0.0f));
  EXPECT_NEAR(m.normals[0].x, want.x, 1e-6);
  EXPECT_NEAR(m.normals[0].y, want.y, 1e-6);
}

TEST(Texture, PngIsDecodedFromSrgbAndVIsFlipped) {
  // A 2×2 PNG: top row red-ish / green-ish, bottom row blue-ish / grey. The
  // 8-bit codes are chosen by encoding, so decoding gives them back exactly.
  const auto dir = test::temp_dir("geometry_texture");
  const auto file = dir / "tex.png";
  Image img = make_image(2, 2);
  auto set = [&](int x, int y, float r, float g, float b) {
    img.at(x, y, 0) = r;
    img.at(x, y, 1) = g;
    img.at(x, y, 2) = b;
  };
  // Linear values of 8-bit codes 200, 100, 50, 0, 255, 128.
  const float c200 = srgb_decode(200.0f / 255.0f), c100 = srgb_decode(100.0f / 255.0f);
  const float c50 = srgb_decode(50.0f / 255.0f), c128 = srgb_decode(128.0f / 255.0f);
  set(0, 0, c200, 0.0f, 0.0f);  // top-left
  set(1, 0, 0.0f, c100, 0.0f);  // top-right
  set(0, 1, 0.0f, 0.0f, c50);   // bottom-left
  set(1, 1, c128, c128, 1.0f);  // bottom-right
  write_image(file, img);

  const Texture tex = Texture::load(file);
  ASSERT_EQ(tex.width(), 2);
  ASSERT_EQ(tex.height(), 2);
  EXPECT_TRUE(tex.srgb_source());
  // Exact values of the sRGB curve (IEC 61966-2-1) for code 200, 100, 50.
  const double want200 = std::pow((200.0 / 255.0 + 0.055) / 1.055, 2.4);
  const double want100 = std::pow((100.0 / 255.0 + 0.055) / 1.055, 2.4);
  const double want50 = std::pow((50.0 / 255.0 + 0.055) / 1.055, 2.4);
  EXPECT_NEAR(tex.texel(0, 0).r, want200, 1e-6);
  EXPECT_NEAR(want200, 0.577580, 1e-6);  // the number itself, not just self-consistency
  // uv (0, 0) is the image's bottom-left: texel centres sit at (x+½)/w, 1 − (y+½)/h.
  auto near3 = [](glm::dvec3 a, glm::dvec3 b) { return glm::length(a - b) < 1e-6; };
  EXPECT_TRUE(near3(tex.lookup({0.25, 0.25}), {0, 0, want50})) << "bottom-left texel";
  EXPECT_TRUE(near3(tex.lookup({0.25, 0.75}), {want200, 0, 0})) << "top-left texel";
  EXPECT_TRUE(near3(tex.lookup({0.75, 0.75}), {0, want100, 0})) << "top-right texel";
  EXPECT_TRUE(near3(tex.lookup({0.75, 0.25}), {c128, c128, 1.0})) << "bottom-right texel";
  // Bilinear between the two top texels, in linear space.
  EXPECT_TRUE(near3(tex.lookup({0.5, 0.75}), {0.5 * want200, 0.5 * want100, 0}));
  // Wrap: u = 0 is halfway between the last and the first column; whole
  // repeats change nothing.
  EXPECT_TRUE(near3(tex.lookup({0.0, 0.75}), {0.5 * want200, 0.5 * want100, 0}));
  EXPECT_TRUE(near3(tex.lookup({-2.25, 3.25}), tex.lookup({0.75, 0.25})));
  EXPECT_TRUE(near3(tex.lookup({0.25, 1.0}), 0.5 * (tex.texel(0, 0) + tex.texel(0, 1))));

  // The GPU packing round-trips the 8-bit codes and keeps row 0 first.
  const std::vector<uint8_t> rgba = tex.rgba8_srgb();
  ASSERT_EQ(rgba.size(), 16u);
  EXPECT_EQ(rgba[0], 200);
  EXPECT_EQ(rgba[4 + 1], 100);
  EXPECT_EQ(rgba[8 + 2], 50);
  EXPECT_EQ(rgba[12 + 0], 128);
  EXPECT_EQ(rgba[3], 255);
  EXPECT_FLOAT_EQ(tex.rgba32f()[0], float(tex.texel(0, 0).r));
  EXPECT_EQ(tex.rgba16f().size(), 16u);
}

TEST(Texture, ExrIsLinearAndErrorsNameTheFile) {
  const auto dir = test::temp_dir("geometry_texture_exr");
  const auto file = dir / "tex.exr";
  Image img = make_image(1, 2);
  img.at(0, 0, 0) = 2.5f;  // top: over 1, linear
  img.at(0, 1, 1) = 0.25f;
  write_image(file, img);
  const Texture tex = Texture::load(file);
  EXPECT_FALSE(tex.srgb_source());
  EXPECT_DOUBLE_EQ(tex.lookup({0.5, 0.75}).r, 2.5);
  EXPECT_DOUBLE_EQ(tex.lookup({0.5, 0.25}).g, 0.25);

  const auto missing = dir / "missing.png";
  std::string msg = input_error_of([&] { Texture::load(missing); });
  EXPECT_NE(msg.find(missing.string()), std::string::npos) << msg;
  const auto junk = dir / "junk.png";
  test::write_file(junk, "not an image");
  msg = input_error_of([&] { Texture::load(junk); });
  EXPECT_NE(msg.find(junk.string()), std::string::npos) << msg;
}
