// shaders/lights.glsl against host/light/: the same uniforms give the same
// environment directions and emission points, with the same pdfs (float
// tolerance), under the validation layers (shaders/test_lights.comp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "render/vulkan/Context.h"
#include "render/vulkan/LightPacking.h"
#include "render/vulkan/Memory.h"
#include "scene/MediumVolume.h"
#include "scene/Scene.h"
#include "shared/light_types.h"
#include "support/GpuCompute.h"
#include "support/LightScenes.h"
#include "volume/StoredVolume.h"

using namespace pyrolume;
using namespace pyrolume::vk;

namespace {

struct LightBlock {
  gpu::GpuEnvironment env;
  gpu::GpuEmissionCdf emission;
};
static_assert(sizeof(LightBlock) == 192);

struct Query {
  glm::vec4 u, u3, env_dir, dir, point;
  glm::vec4 env_s, env_r, env_q, em_s, em_q;
};
static_assert(sizeof(Query) == 160);

// A sky gradient, a black band at the bottom and a small bright sun.
Image sky(int W, int H) {
  return test::sky_image(
      W, H, [](double u, double v) { return glm::dvec3(0.1 + 0.5 * (1 - v), 0.2 + 0.3 * u, 0.9 - 0.6 * v); },
      [&](int, int j) { return j > H * 3 / 4; }, {{0.62, 0.21}, 0.002, {50.0, 45.0, 30.0}});
}

// A small emissive grid with a rotated, sheared, anisotropic map and its own
// temperature lattice.
EmissionCdf skewed_fire() {
  DenseGrid d;
  d.dims = {10, 9, 8};
  d.origin = {-4, 1, 3};
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), glm::dvec3(0.5, 1.0, -2.0));
  m = glm::rotate(m, 0.7, glm::normalize(glm::dvec3(-1, 2, 0.5)));
  glm::dmat4 shear(1.0);
  shear[2][0] = -0.3;
  d.index_to_world = m * shear * glm::scale(glm::dmat4(1.0), glm::dvec3(0.1, 0.15, 0.12));
  d.world_to_index = glm::inverse(d.index_to_world);
  d.values.assign(d.texel_count(), 0.0f);
  std::mt19937 rng(21);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  for (int k = 1; k < d.dims.z - 1; ++k)
    for (int j = 1; j < d.dims.y - 1; ++j)
      for (int i = 1; i < d.dims.x - 1; ++i)
        d.values[(size_t(k) * d.dims.y + j) * d.dims.x + i] = U(rng) < 0.3f ? 0.0f : U(rng);
  DenseGrid t = d;
  t.origin = {0, 0, 0};
  t.index_to_world = d.index_to_world * glm::translate(glm::dmat4(1.0), glm::dvec3(-4.4, 0.6, 2.5)) *
                     glm::scale(glm::dmat4(1.0), glm::dvec3(1.5));
  t.world_to_index = glm::inverse(t.index_to_world);
  for (float& v : t.values) v = 2.0f * U(rng);
  return EmissionCdf::build(d, &t, test::temperature_emission({1.0, 1.5, 2.0}, 700.0, 2.0));
}

void run_queries(Context& ctx, const EnvironmentMap& env, const EmissionCdf& cdf, std::vector<Query>& queries) {
  LightBlock block{pack_gpu_environment_header(env), pack_gpu_emission_header(cdf)};
  Buffer ubo =
      test::filled_buffer(ctx, &block, sizeof block, "light block", MemoryKind::HostVisible,
                          VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  Buffer env_texels = test::filled_buffer(ctx, pack_gpu_environment_texels(env), "env_texels");
  Buffer env_cdf = test::filled_buffer(ctx, env.cdf(), "env_cdf");
  Buffer em_cdf = test::filled_buffer(ctx, cdf.cluster_cdf(), "emission_cdf");
  Buffer em_cells = test::filled_buffer(ctx, cdf.entry_cells(), "emission_cells");
  Buffer em_pmf = test::filled_buffer(ctx, cdf.cluster_pmf(), "emission_pmf");
  Buffer em_clusters = test::filled_buffer(ctx, pack_gpu_emission_clusters(cdf), "emission_clusters");
  Buffer qbuf = test::in_out_buffer(ctx, queries, "queries");
  test::run_compute(ctx, "test_lights.comp",
                    {{&ubo, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
                     {&env_texels},
                     {&env_cdf},
                     {&em_cdf},
                     {&em_cells},
                     {&em_pmf},
                     {&qbuf},
                     {&em_clusters}},
                    uint32_t(queries.size()), {}, "test_lights");
  test::read_back(qbuf, queries);
}

double rel(double a, double b) { return std::abs(a - b) / std::max({std::abs(a), std::abs(b), 1e-30}); }

// Whether the CPU pdf of some direction within 3e-4 rad of d is gpu_pdf: the
// GPU's float atan/acos (Vulkan allows thousands of ulp) move (u, v) by ~1e-5,
// enough to cross a texel edge now and then.
bool pdf_nearby(const EnvironmentMap& env, const glm::dvec3& d, double gpu_pdf) {
  for (int a = 0; a < 3; ++a)
    for (double sgn : {-1.0, 1.0}) {
      glm::dvec3 e(0.0);
      e[a] = 3e-4 * sgn;
      if (rel(env.pdf(glm::normalize(d + e)), gpu_pdf) < 2e-3) return true;
    }
  return false;
}

void check(const EnvironmentMap& env, const EmissionCdf& cdf, uint32_t seed) {
  const uint64_t before = Context::total_validation_messages();
  Context ctx(test::validated());
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> U(0.0f, 1.0f), Uin(0.01f, 0.99f);
  const int n = 4096;
  std::vector<Query> q(n);
  std::vector<EmissionSample> cpu_points(n);
  const double extent = glm::length(cdf.cell_to_world(glm::dvec3(cdf.cells())) - cdf.cell_to_world(glm::dvec3(0.0)));
  for (int k = 0; k < n; ++k) {
    q[k].u = {U(rng), U(rng), U(rng), U(rng)};
    q[k].u3 = {Uin(rng), Uin(rng), Uin(rng), 0.0f};
    const float z = 2 * U(rng) - 1, phi = 6.2831853f * U(rng), s = std::sqrt(std::max(0.0f, 1 - z * z));
    // Receivers inside the grid (even k: a point of the static distribution)
    // and outside it, then a point drawn from there: the direction toward it
    // has a direction pdf > 0.
    const glm::vec3 inside = glm::vec3(cdf.sample(U(rng), {Uin(rng), Uin(rng), Uin(rng)}).p);
    q[k].env_dir = {s * std::cos(phi), s * std::sin(phi), z, 0.0f};
    const glm::vec3 o = k % 2 ? inside + float(2.0 * extent) * glm::vec3(q[k].env_dir) : inside;
    cpu_points[k] = cdf.sample_from(glm::dvec3(o), U(rng), U(rng), {Uin(rng), Uin(rng), Uin(rng)});
    const glm::vec3 v = glm::vec3(cpu_points[k].p) - o;
    q[k].dir = glm::vec4(glm::normalize(v), glm::length(v));
    q[k].point = glm::vec4(o, 0.0f);
  }
  run_queries(ctx, env, cdf, q);
  int env_pdf_boundary = 0, query_pdf_boundary = 0, direction_pdfs = 0, neighbour_cells = 0;
  for (int k = 0; k < n; ++k) {
    const Query& g = q[k];
    // Environment sample: same texel (same float CDF search), same direction.
    const EnvSample s = env.sample({double(g.u.x), double(g.u.y)});
    ASSERT_GT(s.pdf, 0.0);
    ASSERT_LT(glm::length(glm::dvec3(glm::vec3(g.env_s)) - s.dir), 2e-4) << k;
    ASSERT_LT(rel(g.env_s.w, s.pdf), 2e-3) << k << ": " << g.env_s.w << " vs " << s.pdf;
    for (int c = 0; c < 3; ++c) ASSERT_NEAR(g.env_r[c], s.radiance[c], 1e-3 * (1e-2 + s.radiance[c])) << k;
    // env_pdf of the GPU's own direction: equal, or at a texel edge the pdf of
    // the texel next to it.
    if (rel(g.env_r.w, g.env_s.w) > 2e-3) {
      ++env_pdf_boundary;
      ASSERT_TRUE(pdf_nearby(env, s.dir, g.env_r.w)) << k;
    }
    // env_radiance / env_pdf of a given direction.
    const glm::dvec3 d(glm::vec3(g.env_dir));
    // The GPU's float atan/acos (Vulkan allows thousands of ulp) move (u, v) by
    // ~1e-5, which matters at the sun's and the black band's edges: the GPU
    // value must lie within the CPU's over directions 3e-4 rad around.
    glm::dvec3 lo = env.radiance(d), hi = lo;
    for (int a = 0; a < 3; ++a)
      for (double sgn : {-1.0, 1.0}) {
        glm::dvec3 e(0.0);
        e[a] = 3e-4 * sgn;
        const glm::dvec3 L = env.radiance(glm::normalize(d + e));
        lo = glm::min(lo, L);
        hi = glm::max(hi, L);
      }
    for (int c = 0; c < 3; ++c) {
      ASSERT_GE(g.env_q[c], lo[c] - 1e-4 * (1e-2 + lo[c])) << k;
      ASSERT_LE(g.env_q[c], hi[c] + 1e-4 * (1e-2 + hi[c])) << k;
    }
    if (rel(g.env_q.w, env.pdf(d)) > 2e-3) {
      ++query_pdf_boundary;
      ASSERT_TRUE(pdf_nearby(env, d, g.env_q.w)) << k;
    }

    // Emission sample from the receiver: the same normaliser, cell, point and pdf.
    const glm::dvec3 o(glm::vec3(g.point));
    ASSERT_LT(rel(g.point.w, cdf.receiver_norm(o)), 1e-5) << k;
    const EmissionSample m = cdf.sample_from(o, double(g.u.z), double(g.u.w), glm::dvec3(glm::vec3(g.u3)));
    uint32_t gpu_cell;
    std::memcpy(&gpu_cell, &g.em_q.x, 4);
    if (int64_t(gpu_cell) == m.cell) {
      ASSERT_LT(glm::length(glm::dvec3(glm::vec3(g.em_s)) - m.p), 1e-5 * extent) << k;
      ASSERT_LT(rel(g.em_s.w, m.pdf), 1e-5) << k;
    } else {
      // u·norm (float on the GPU, double here) fell on a step between two
      // clusters: the neighbouring one, with its own pdf.
      ++neighbour_cells;
      ASSERT_LT(rel(g.em_s.w, cdf.pdf_from(o, glm::dvec3(glm::vec3(g.em_s)))), 1e-5) << k;
    }
    ASSERT_LT(rel(g.em_q.y, g.em_s.w), 1e-5) << k;  // emission_pdf(sampled point), away from faces
    ASSERT_LT(rel(g.em_q.z, cpu_points[k].pdf), 1e-5) << k;
    // The pdf of a direction: the same walk over the cells in float. Where a
    // ray grazes a cell edge the two may take a cell more or less.
    const glm::dvec3 toward(glm::vec3(g.dir));
    const double dir_pdf = cdf.direction_pdf(o, toward);
    ASSERT_GT(dir_pdf, 0.0) << k;  // the ray passes through the sampled point
    if (rel(g.em_q.w, dir_pdf) > 1e-3) ++direction_pdfs;
    ASSERT_LT(rel(g.em_q.w, dir_pdf), 2e-2) << k << ": " << g.em_q.w << " vs " << dir_pdf;
  }
  std::printf("direction pdfs off by more than 1e-3: %d of %d; neighbouring cells sampled: %d\n", direction_pdfs, n,
              neighbour_cells);
  EXPECT_LE(neighbour_cells, n / 200);
  EXPECT_LE(direction_pdfs, n / 100);
  // The float (u, v) lands across a texel edge for ~0.3 % of directions at 512 × 256.
  std::printf("env pdf at a texel edge: %d sampled, %d given directions of %d\n", env_pdf_boundary,
              query_pdf_boundary, n);
  EXPECT_LE(env_pdf_boundary, n / 50);
  EXPECT_LE(query_pdf_boundary, n / 50);
  EXPECT_EQ(ctx.validation_messages(), 0u);
  EXPECT_EQ(Context::total_validation_messages(), before);
}

}  // namespace

TEST(LightGpu, SkewedGridAndRotatedSkyMatchTheCpu) {
  EnvironmentMap env = EnvironmentMap::from_image(sky(128, 64), 2.0, 30.0);
  EmissionCdf cdf = skewed_fire();
  ASSERT_FALSE(cdf.empty());
  // One cluster (the distribution the same from everywhere) and clusters of 3³ cells.
  check(env, cdf.clustered(16), 1);
  check(env, cdf.clustered(3), 4);
}

TEST(LightGpu, YUpSkyMatchesTheCpu) {
  EnvironmentMap env = EnvironmentMap::from_image(sky(128, 64), 2.0, 30.0, /*zenith_y=*/true);
  check(env, skewed_fire().clustered(16), 5);
}

TEST(LightGpu, DemoFireMatchesTheCpu) {
  const Scene scene = load_scene(std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/scenes/fire.json");
  const StoredVolume vol = load_stored_volume(scene.media.at(0));
  EmissionCdf cdf = EmissionCdf::build(scene.media[0], vol);
  ASSERT_FALSE(cdf.empty());
  EnvironmentMap env = EnvironmentMap::from_image(sky(512, 256), 1.0, -75.0);
  check(env, cdf.clustered(16), 2);
  // What the renderers sample: blocks of cells in clusters.
  check(env, EmissionCdf::build_light(scene.media[0], vol), 3);
}
