// Hard cases of geometry (docs/robustness.md "Hard cases"), on the CPU
// reference and on Vulkan: a one-voxel grid, a 1×1×N grid, extreme medium
// transforms, the camera inside a volume, on its boundary and 1e5 units away,
// and rays grazing bounding-box faces. Every case has a closed form
// (tests/support: the exact trilinear field integrated along each ray, pixel
// averaged); every render also asserts finite output and nonfinite_samples == 0.
#include <cmath>
#include <cstdio>
#include <numbers>

#include <glm/gtc/packing.hpp>
#include <gtest/gtest.h>

#include "hardcases/HardCaseFixture.h"
#include "scene/MediumVolume.h"
#include "volume/VdbLoader.h"

namespace pyrolume {
namespace {

using hard::pooled;

// A grid's outermost pixels see only the far tail of its trilinear ramp:
// absorption there has probability ~1e-5 per sample, so all samples can be
// the background (SE = 0) while the exact mean differs from it slightly.
// Samples are the background or Le, so they differ from each other by at most
// |Le − bg| <= Le + bg (HardCaseFixture.h: allow_unseen_rare_events).
glm::dvec3 sample_range(const Scene& s) {
  return s.media.at(0).emission.scale * s.media.at(0).emission.rgb.value() + s.background;
}

template <class B>
class HardGeometry : public hard::HardCase<B> {};
TYPED_TEST_SUITE(HardGeometry, hard::Backends, hard::BackendNames);

float as_half(float v) { return glm::unpackHalf1x16(glm::packHalf1x16(v)); }

// The exact image of a single grid medium whose (untransformed) field is `f`,
// placed in the world by `M` (the medium transform): a world ray (o, d) is the
// ray (M⁻¹o, M⁻¹d) in the grid's own frame with the same parameter t, so
// τ = f.optical_depth(M⁻¹o, M⁻¹d) (|M⁻¹d| need not be 1).
template <class Field>
std::function<glm::dvec3(int, int)> grid_exact(const Scene& s, const Field& f, const glm::dmat4& M = glm::dmat4(1.0)) {
  const glm::dmat4 Mi = glm::inverse(M);
  return test::exact_image(s, [&s, f, Mi](const glm::dvec3& o, const glm::dvec3& d, int* sig) {
    const glm::dvec3 ol(Mi * glm::dvec4(o, 1.0)), dl(Mi * glm::dvec4(d, 0.0));
    if (sig) *sig = f.signature(ol, dl);
    return test::uniform_albedo_radiance(s, f.optical_depth(ol, dl));
  });
}

// One active voxel: the trilinear field is a tent two voxels wide on each
// axis (the renderers' one-texel zero padding), nowhere constant.
TYPED_TEST(HardGeometry, OneVoxelGrid) {
  const test::Lattice lat{1.0, {0.1, -0.2, 0.05}};
  const test::VoxelBox one{{0, 0, 0}, {0, 0, 0}};
  auto value = [](int, int, int) { return 2.0f; };
  test::write_vdb(this->dir / "one.vdb", {test::make_float_grid("density", lat, one, value)});
  Scene s = test::vdb_base_scene(16, 16, 256);
  s.camera.position = {1.5, 1.0, -4.0};
  s.camera.look_at = lat.world(glm::dvec3(0.0));
  s.background = {0.05, 0.1, 0.2};
  s.media.push_back(test::vdb_medium("voxel", this->dir / "one.vdb", {0.4, 0.8, 1.6}, {0, 0, 0}, 0.0,
                                     glm::dvec3(1.0, 0.6, 0.3), 1.5));
  const RenderResult r = this->expect_closed_form(s, grid_exact(s, test::TrilinearVoxelField(lat, one, value)),
                                                  "one voxel", pooled(0.01), sample_range(s));
  this->expect_rejected(
      r,
      hard::allow_unseen_rare_events(
          r, grid_exact(s, test::TrilinearVoxelField(lat, one, [](int, int, int) { return 2.2f; })), sample_range(s)),
      "10 % denser", pooled(0.01));
}

// A 1×1×32 grid (a rod of one voxel's width with a density ramp along it):
// seen from the side, and end-on (rays run 32 voxels along a texture that is
// 3 texels wide in x and y, and through a majorant grid of 1-texel columns).
TYPED_TEST(HardGeometry, OneByOneByNGrid) {
  const test::Lattice lat{0.1, {0.03, -0.02, 0.0}};
  const test::VoxelBox rod{{0, 0, 0}, {0, 0, 31}};
  auto value = [](int, int, int k) { return as_half(0.5f + 0.1f * float(k)); };
  test::write_vdb(this->dir / "rod.vdb", {test::make_float_grid("density", lat, rod, value)});
  const test::TrilinearVoxelField f(lat, rod, value);
  const glm::dvec3 axis = lat.world({0.0, 0.0, 15.5});

  Scene side = test::vdb_base_scene(32, 16, 256);
  side.camera.position = axis + glm::dvec3(-4.0, 0.01, 0.0);
  side.camera.look_at = axis;
  side.camera.fov_deg = 2.0 * std::atan(0.4 / 4.0) * 180.0 / std::numbers::pi;
  side.background = {0.05, 0.1, 0.2};
  side.media.push_back(test::vdb_medium("rod", this->dir / "rod.vdb", {2.0, 4.0, 8.0}, {0, 0, 0}, 0.0,
                                        glm::dvec3(1.0, 0.6, 0.3), 1.5));
  this->expect_closed_form(side, grid_exact(side, f), "rod, side view", pooled(0.01), sample_range(side));

  Scene end = side;
  end.film.width = end.film.height = 16;
  end.camera.position = lat.world({0.1, 0.05, -30.0});
  end.camera.look_at = lat.world({0.0, 0.0, 15.5});
  end.camera.fov_deg = 2.0 * std::atan(0.2 / 3.0) * 180.0 / std::numbers::pi;
  end.media[0].sigma_a = {0.1, 0.3, 0.9};
  this->expect_closed_form(end, grid_exact(end, f), "rod, end-on", pooled(0.01), sample_range(end));
}

// The constant-box cases take 512 spp: at 256 one pixel's Bernoulli-like
// absorption samples reach |z| > 4 in several of these similar scenes at
// once (the same sample streams; the tails are heavier than Gaussian).

// Extreme medium transforms on the constant box, the camera carried along by
// the same map: uniform scale 1e-4 and 1e4 (σ divided by the scale, so the
// optical depths stay the same), a non-uniform scale, and 45° about each axis.
// Closed form: the untransformed field along the rays mapped back by M⁻¹.
TYPED_TEST(HardGeometry, ExtremeTransforms) {
  struct Case {
    const char* what;
    Transform t;
  };
  auto tf = [](glm::dvec3 scale, glm::dvec3 rotate, glm::dvec3 translate) {
    Transform t;
    t.scale = scale;
    t.rotate_deg = rotate;
    t.translate = translate;
    return t;
  };
  const Case cases[] = {
      {"scale 1e-4", tf(glm::dvec3(1e-4), {0, 0, 0}, {3e-5, -2e-5, 1e-5})},
      {"scale 1e4", tf(glm::dvec3(1e4), {0, 0, 0}, {2e4, -1e4, 5e3})},
      {"non-uniform scale", tf({0.4, 2.5, 1.0}, {0, 0, 0}, {0.1, 0.2, -0.3})},
      {"rotate 45 about x", tf(glm::dvec3(1.0), {45, 0, 0}, {0, 0, 0})},
      {"rotate 45 about y", tf(glm::dvec3(1.0), {0, 45, 0}, {0, 0, 0})},
      {"rotate 45 about z", tf(glm::dvec3(1.0), {0, 0, 45}, {0, 0, 0})},
  };
  const glm::dvec3 sigma_a{0.8, 1.6, 3.2};
  for (const Case& c : cases) {
    Scene s = this->constant_box_scene(16, 16, 512, sigma_a, {0, 0, 0});
    const glm::dmat4 M = medium_transform_matrix(c.t);
    const double iso = std::cbrt(std::abs(glm::determinant(glm::dmat3(M))));
    s.media[0].transform = c.t;
    s.media[0].sigma_a = sigma_a / iso;
    s.camera.position = glm::dvec3(M * glm::dvec4(s.camera.position, 1.0));
    s.camera.look_at = glm::dvec3(M * glm::dvec4(s.camera.look_at, 1.0));
    s.camera.up = glm::normalize(glm::dvec3(M * glm::dvec4(s.camera.up, 0.0)));
    const RenderResult r = this->expect_closed_form(s, grid_exact(s, this->field(), M), c.what, pooled(0.01));
    this->expect_rejected(r, grid_exact(s, this->field()), "transform ignored", pooled(0.01));
  }
}

// The camera inside the grid (its constant region), on the boundary of the
// grid's support and of its constant region (rays start exactly on a face),
// on a homogeneous sphere's surface looking along the tangent plane (half
// the rays enter, half leave at once) and on a homogeneous box's face.
TYPED_TEST(HardGeometry, CameraInsideAndOnTheBoundary) {
  const Bounds sup = test::support_box(this->lat, this->box), cen = test::centre_box(this->lat, this->box);
  struct Place {
    const char* what;
    glm::dvec3 position;
  };
  for (const Place& p : {Place{"camera inside", {0.1, 0.05, -0.3}}, Place{"camera on support face", {0.1, 0.05, sup.min.z}},
                         Place{"camera on constant-region face", {0.1, 0.05, cen.min.z}}}) {
    Scene s = this->constant_box_scene(16, 16, 1024, {0.8, 1.6, 3.2}, {0, 0, 0});
    s.camera.position = p.position;
    s.camera.look_at = p.position + glm::dvec3(0.2, 0.15, 1.0);
    s.camera.fov_deg = 70.0;
    this->expect_closed_form(s, test::constant_box_exact(s, this->field()), p.what, pooled(0.01));
  }
  Scene sphere = test::analytic_base_scene(16, 16, 256);
  sphere.background = {0.05, 0.1, 0.2};
  sphere.media.push_back(test::homogeneous_sphere("ball", {0, 0, 0}, 1.0, {0.4, 1.0, 2.5}, {0, 0, 0}, 0.0,
                                                  glm::dvec3(1.0, 0.55, 0.25), 1.5));
  sphere.camera.position = {0.0, 0.0, -1.0};
  sphere.camera.look_at = {1.0, 0.3, -1.0};
  sphere.camera.fov_deg = 60.0;
  this->expect_closed_form(sphere, test::single_collision_exact(sphere), "camera on sphere surface", pooled(0.01));
  Scene box = test::analytic_base_scene(16, 16, 256);
  box.background = {0.05, 0.1, 0.2};
  box.media.push_back(test::homogeneous_box("block", glm::dvec3(-1.0), glm::dvec3(1.0), {0.3, 0.9, 2.0}, {0, 0, 0},
                                            0.0, glm::dvec3(0.4, 1.0, 1.6), 1.2));
  box.camera.position = {0.2, 0.1, -1.0};
  box.camera.look_at = {0.5, 0.4, 1.0};
  box.camera.fov_deg = 60.0;
  this->expect_closed_form(box, test::single_collision_exact(box), "camera on box face", pooled(0.01));
}

// The camera 1e5 units away with a fov that frames the grid (t ≈ 1e5: float32
// on the GPU resolves ~8e-3 units there).
TYPED_TEST(HardGeometry, CameraFarAway) {
  Scene s = this->constant_box_scene(16, 16, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  s.camera.position = {0.3, 0.2, -1.0e5};
  s.camera.look_at = {0.0, 0.0, 0.0};
  s.camera.fov_deg = 2.0 * std::atan(1.0 / 1.0e5) * 180.0 / std::numbers::pi;
  this->expect_closed_form(s, test::constant_box_exact(s, this->field()), "camera 1e5 away", pooled(0.01));
}

// Rays grazing bounding-box faces: the camera in the plane of a face of the
// grid's support box and of its constant region, and in the planes of two
// faces of a homogeneous box, looking along them (the middle row and column
// of pixels graze).
TYPED_TEST(HardGeometry, RaysGrazingBoundingBoxFaces) {
  const Bounds sup = test::support_box(this->lat, this->box), cen = test::centre_box(this->lat, this->box);
  Scene s = this->constant_box_scene(16, 16, 512, {0.8, 1.6, 3.2}, {0, 0, 0});
  s.camera.position = {cen.max.x, sup.max.y, -4.0};
  s.camera.look_at = {cen.max.x, sup.max.y, 0.0};
  s.camera.fov_deg = 15.0;
  this->expect_closed_form(s, test::constant_box_exact(s, this->field()), "grazing grid faces", pooled(0.01));

  Scene h = test::absorbing_box_scene(16, 16, 256);
  const Bounds& b = h.media[0].bounds;
  h.camera.position = {b.max.x, b.max.y, -4.0};
  h.camera.look_at = {b.max.x, b.max.y, 0.0};
  h.camera.fov_deg = 20.0;
  this->expect_closed_form(h, test::single_collision_exact(h), "grazing box faces", pooled(0.01));
}

}  // namespace
}  // namespace pyrolume
