// The emissive volume as a light (host/light/EmissionCdf): the point density
// against the cell weights (chi-square, tests/support/Stats.h), pdf(point) vs
// the sampled pdf, coverage of every emitting point (max over the corners and
// over the temperature footprint), the empty case, and the demo fire.
#include <gtest/gtest.h>

#include <chrono>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <cstdio>
#include <limits>
#include <random>

#include <glm/gtc/matrix_transform.hpp>

#include "color/Blackbody.h"
#include "color/ColorSpace.h"
#include "light/EmissionCdf.h"
#include "render/vulkan/LightPacking.h"
#include "scene/MediumVolume.h"
#include "scene/Scene.h"
#include "support/LightScenes.h"
#include "support/Stats.h"
#include "volume/StoredVolume.h"

using namespace pyrolume;

namespace {

// An affine index->world map with rotation, shear, anisotropic scale and an offset.
glm::dmat4 skewed_map(double voxel, const glm::dvec3& translate) {
  glm::dmat4 m = glm::translate(glm::dmat4(1.0), translate);
  m = glm::rotate(m, 0.4, glm::normalize(glm::dvec3(1, 2, 3)));
  glm::dmat4 shear(1.0);
  shear[1][0] = 0.2;  // x += 0.2 y
  m = m * shear * glm::scale(glm::dmat4(1.0), glm::dvec3(voxel, voxel * 1.3, voxel * 0.8));
  return m;
}

DenseGrid make_grid(glm::ivec3 dims, glm::ivec3 origin, const glm::dmat4& index_to_world) {
  DenseGrid g;
  g.name = "g";
  g.dims = dims;
  g.origin = origin;
  g.index_to_world = index_to_world;
  g.world_to_index = glm::inverse(index_to_world);
  g.values.assign(g.texel_count(), 0.0f);
  return g;
}

float& at(DenseGrid& g, int i, int j, int k) {
  return g.values[(size_t(k) * g.dims.y + j) * g.dims.x + i];
}

// Random density with zeros, padding 0 on every side (as the loader stores it).
DenseGrid random_density(uint32_t seed) {
  DenseGrid g = make_grid({9, 8, 7}, {-3, 2, 5}, skewed_map(0.25, {1.0, -0.5, 2.0}));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> U(0.0f, 1.0f);
  for (int k = 1; k < g.dims.z - 1; ++k)
    for (int j = 1; j < g.dims.y - 1; ++j)
      for (int i = 1; i < g.dims.x - 1; ++i) at(g, i, j, k) = U(rng) < 0.4f ? 0.0f : U(rng);
  return g;
}

// A temperature grid at its own coarser, offset lattice over the same region.
DenseGrid random_temperature(const DenseGrid& density, uint32_t seed) {
  glm::dmat4 m = density.index_to_world * glm::translate(glm::dmat4(1.0), glm::dvec3(-3.3, 2.2, 4.6)) *
                 glm::scale(glm::dmat4(1.0), glm::dvec3(1.7));
  DenseGrid t = make_grid({7, 6, 6}, {0, 0, 0}, m);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> U(0.0f, 2.0f);
  for (float& v : t.values) v = U(rng);  // T = v·1000 K: below and above the 800 K cutoff
  return t;
}

EmissionParams temperature_params() {
  EmissionParams p = test::temperature_emission({1.0, 2.0, 0.5}, 800.0, 3.0);
  p.temperature.offset = 0.0;
  p.emission.blackbody = BlackbodyMode::Seed;
  return p;
}

EmissionParams rgb_params() {
  EmissionParams p;
  p.sigma_a = {1.0, 2.0, 0.5};
  p.emits_rgb = true;
  p.Le_rgb = {2.0, 1.0, 0.25};
  return p;
}

// The emission CDF of `density` with a random temperature grid (seed
// temperature_seed) under temperature_params().
EmissionCdf random_fire_cdf(const DenseGrid& density, uint32_t temperature_seed) {
  const DenseGrid t = random_temperature(density, temperature_seed);
  return EmissionCdf::build(density, &t, temperature_params());
}

// The emitted radiance per unit length at p, as the renderers compute it
// (host/render/cpu/Media.h grid_sigma_a_Le), luminance only.
double emitted_luminance(const DenseGrid& density, const DenseGrid* temperature, const EmissionParams& p,
                         const glm::dvec3& x) {
  const double rho = density.sample_world(x);
  if (!(rho > 0.0)) return 0.0;
  glm::dvec3 Le = p.Le_rgb;
  if (!p.emits_rgb) {
    const double T = (temperature->sample_world(x) - p.temperature.offset) * p.temperature.scale;
    if (!(T > p.temperature.cutoff_k) || T < 100.0) return 0.0;
    Le = p.emission.scale * color::blackbody_rgb_5nm(std::min(T, 1e6), p.emission.blackbody);
  }
  return color::srgb_luminance(p.sigma_a * rho * Le);
}

glm::ivec3 cell_of(const DenseGrid& density, const glm::dvec3& p) {
  return glm::ivec3(glm::floor(glm::dvec3(density.world_to_index * glm::dvec4(p, 1.0)) - glm::dvec3(density.origin)));
}

// Chi-square of sampled points against per-cell weights, each cell split into
// 2×2×2 sub-bins (uniformity inside the cell is tested too).
test::ChiSquareResult chi_square_cells(const EmissionCdf& cdf, const DenseGrid& density,
                                       const std::function<double(glm::ivec3)>& weight, int n, uint32_t seed) {
  const glm::ivec3 C = cdf.cells();
  const size_t nbins = cdf.cell_count() * 8;
  std::vector<double> observed(nbins, 0.0), expected(nbins, 0.0);
  double total = 0.0;
  for (int k = 0; k < C.z; ++k)
    for (int j = 0; j < C.y; ++j)
      for (int i = 0; i < C.x; ++i) total += weight({i, j, k});
  for (int k = 0; k < C.z; ++k)
    for (int j = 0; j < C.y; ++j)
      for (int i = 0; i < C.x; ++i)
        for (int s = 0; s < 8; ++s) expected[size_t(cdf.linear_cell({i, j, k})) * 8 + s] = n * weight({i, j, k}) / total / 8;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < n; ++k) {
    EmissionSample s = cdf.sample(U(rng), {U(rng), U(rng), U(rng)});
    const glm::dvec3 c = glm::dvec3(density.world_to_index * glm::dvec4(s.p, 1.0)) - glm::dvec3(density.origin);
    const glm::ivec3 cell = glm::ivec3(glm::floor(c));
    const glm::dvec3 f = c - glm::floor(c);
    if (glm::any(glm::lessThan(cell, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(cell, C))) {
      ADD_FAILURE() << "sample outside the grid";
      continue;
    }
    const int sub = (f.x >= 0.5) + 2 * (f.y >= 0.5) + 4 * (f.z >= 0.5);
    observed[size_t(cdf.linear_cell(cell)) * 8 + sub] += 1.0;
  }
  return test::chi_square(observed, expected);
}

double corner_max(const DenseGrid& g, glm::ivec3 c) {
  double m = 0.0;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) m = std::max(m, double(g.texel(c.x + i, c.y + j, c.z + k)));
  return m;
}

}  // namespace

TEST(EmissionCdf, ConstantEmissionWeightsAreTheCornerMaximaTimesLuminance) {
  DenseGrid d = random_density(1);
  EmissionParams p = rgb_params();
  EmissionCdf cdf = EmissionCdf::build(d, nullptr, p);
  ASSERT_FALSE(cdf.empty());
  EXPECT_EQ(cdf.cells(), d.dims - 1);
  const double E = color::srgb_luminance(p.sigma_a * p.Le_rgb);
  double sum_pmf = 0.0;
  for (int k = 0; k < cdf.cells().z; ++k)
    for (int j = 0; j < cdf.cells().y; ++j)
      for (int i = 0; i < cdf.cells().x; ++i) {
        EXPECT_NEAR(cdf.cell_weight({i, j, k}), corner_max(d, {i, j, k}) * E, 1e-6);
        sum_pmf += cdf.cell_pmf(cdf.linear_cell({i, j, k}));
      }
  EXPECT_NEAR(sum_pmf, 1.0, 1e-6);
  // |det| of the cell: voxel 0.25 × 0.325 × 0.2 (rotation and shear keep volume).
  EXPECT_NEAR(cdf.cell_volume(), 0.25 * 0.325 * 0.2, 1e-12);
}

TEST(EmissionCdf, PointsFollowTheCellWeightsChiSquare) {
  const DenseGrid d = random_density(2);
  const EmissionCdf cdf = random_fire_cdf(d, 3);
  ASSERT_FALSE(cdf.empty());
  auto w = [&](glm::ivec3 c) { return cdf.cell_weight(c); };
  test::ChiSquareResult r = chi_square_cells(cdf, d, w, 400000, 5);
  std::printf("emission CDF chi-square: %s\n", r.summary().c_str());
  EXPECT_GT(r.p_value, 0.01) << r.summary();
  // The harness can fail: against weights from each cell's first corner only,
  // the same samples are rejected.
  test::ChiSquareResult wrong = chi_square_cells(
      cdf, d, [&](glm::ivec3 c) { return cdf.cell_weight(c) > 0 ? std::max(double(d.texel(c.x, c.y, c.z)), 1e-3) : 0.0; },
      400000, 5);
  EXPECT_LT(wrong.p_value, 1e-6) << wrong.summary();
  // With constant emission the expected weights are independent of the code.
  EmissionCdf rgb = EmissionCdf::build(d, nullptr, rgb_params());
  test::ChiSquareResult r2 = chi_square_cells(rgb, d, [&](glm::ivec3 c) { return corner_max(d, c); }, 400000, 6);
  EXPECT_GT(r2.p_value, 0.01) << r2.summary();
}

TEST(EmissionCdf, PdfOfAPointEqualsTheSampledPdf) {
  const DenseGrid d = random_density(4);
  const EmissionCdf cdf = random_fire_cdf(d, 5);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < 20000; ++k) {
    EmissionSample s = cdf.sample(U(rng), {U(rng), U(rng), U(rng)});
    ASSERT_GT(s.pdf, 0.0);
    ASSERT_EQ(cdf.pdf(s.p), s.pdf) << k;
    ASSERT_EQ(cdf.linear_cell(cell_of(d, s.p)), s.cell);
    ASSERT_NEAR(s.pdf, cdf.cell_pmf(s.cell) / cdf.cell_volume(), 1e-12 * s.pdf);
  }
  // ∫ pdf dV = 1 by Monte Carlo over the grid's cell box: E[pdf]·V_box.
  double acc = 0.0;
  const int n = 200000;
  const glm::dvec3 C(cdf.cells());
  for (int k = 0; k < n; ++k) acc += cdf.pdf(cdf.cell_to_world(C * glm::dvec3(U(rng), U(rng), U(rng))));
  const double V = cdf.cell_volume() * C.x * C.y * C.z;
  EXPECT_NEAR(acc / n * V, 1.0, 0.05);
  EXPECT_EQ(cdf.pdf(cdf.cell_to_world({-0.01, 1, 1})), 0.0);  // outside
  EXPECT_EQ(cdf.pdf(cdf.cell_to_world(C + 0.01)), 0.0);
}

TEST(EmissionCdf, EveryEmittingPointHasPositivePdf) {
  // One density texel and emission blended into the 8 cells around it.
  {
    DenseGrid d = make_grid({9, 9, 9}, {0, 0, 0}, skewed_map(0.5, {0, 0, 0}));
    at(d, 4, 4, 4) = 1.0f;
    EmissionCdf cdf = EmissionCdf::build(d, nullptr, rgb_params());
    EXPECT_EQ(cdf.entry_count(), 8u);
    std::mt19937_64 rng(1);
    std::uniform_real_distribution<double> U(2.5, 5.5);
    int emitting = 0;
    for (int k = 0; k < 20000; ++k) {
      const glm::dvec3 x = cdf.cell_to_world({U(rng), U(rng), U(rng)});
      if (emitted_luminance(d, nullptr, rgb_params(), x) > 0.0) {
        ++emitting;
        ASSERT_GT(cdf.pdf(x), 0.0);
      }
    }
    EXPECT_GT(emitting, 2000);
  }
  // Dense smoke everywhere, one hot texel on a coarser, shifted temperature
  // lattice: every cell its trilinear footprint reaches must be sampleable.
  {
    DenseGrid d = make_grid({12, 12, 12}, {0, 0, 0}, skewed_map(0.5, {0, 0, 0}));
    for (int k = 1; k < 11; ++k)
      for (int j = 1; j < 11; ++j)
        for (int i = 1; i < 11; ++i) at(d, i, j, k) = 1.0f;
    glm::dmat4 m = d.index_to_world * glm::translate(glm::dmat4(1.0), glm::dvec3(0.3, 0.7, 0.45)) *
                   glm::scale(glm::dmat4(1.0), glm::dvec3(2.0));
    DenseGrid t = make_grid({6, 6, 6}, {0, 0, 0}, m);
    at(t, 3, 2, 3) = 1.5f;  // 1500 K; everything else 0 K
    EmissionParams p = temperature_params();
    EmissionCdf cdf = EmissionCdf::build(d, &t, p);
    ASSERT_FALSE(cdf.empty());
    // Cells whose own centre is cold but that the hot texel's footprint
    // reaches: a centre-only weight would miss them.
    std::mt19937_64 rng(2);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    int emitting = 0, cold_centre = 0;
    const glm::dvec3 hot = glm::dvec3(t.index_to_world * glm::dvec4(3, 2, 3, 1));
    const glm::dvec3 hot_c = cdf.world_to_cell(hot);
    for (int k = 0; k < 50000; ++k) {
      const glm::dvec3 c = hot_c + 5.0 * glm::dvec3(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5);
      const glm::dvec3 x = cdf.cell_to_world(c);
      if (emitted_luminance(d, &t, p, x) > 0.0) {
        ++emitting;
        ASSERT_GT(cdf.pdf(x), 0.0) << c.x << " " << c.y << " " << c.z;
        const glm::dvec3 centre = cdf.cell_to_world(glm::floor(c) + 0.5);
        if (emitted_luminance(d, &t, p, centre) == 0.0) ++cold_centre;
      }
    }
    EXPECT_GT(emitting, 300);
    EXPECT_GT(cold_centre, 0);
  }
  // Outside the temperature grid the value reads 0, which this mapping puts
  // above the cutoff (T = (0 + 1)·1000 K): smoke there emits too.
  {
    DenseGrid d = random_density(8);
    DenseGrid t = make_grid({3, 3, 3}, {0, 0, 0}, glm::scale(glm::dmat4(1.0), glm::dvec3(0.01)));
    EmissionParams p = temperature_params();
    p.temperature.offset = -1.0;
    EmissionCdf cdf = EmissionCdf::build(d, &t, p);
    ASSERT_FALSE(cdf.empty());
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const glm::dvec3 C(cdf.cells());
    int emitting = 0;
    for (int k = 0; k < 20000; ++k) {
      const glm::dvec3 x = cdf.cell_to_world(C * glm::dvec3(U(rng), U(rng), U(rng)));
      if (emitted_luminance(d, &t, p, x) > 0.0) {
        ++emitting;
        ASSERT_GT(cdf.pdf(x), 0.0);
      }
    }
    EXPECT_GT(emitting, 5000);
  }
}

TEST(EmissionCdf, NoEmissionGivesNoDistribution) {
  DenseGrid d = random_density(9);
  DenseGrid t = random_temperature(d, 10);
  auto expect_empty = [](const EmissionCdf& cdf, const char* what) {
    EXPECT_TRUE(cdf.empty()) << what;
    EXPECT_EQ(cdf.entry_count(), 0u) << what;
    EXPECT_EQ(cdf.power(), 0.0) << what;
    EXPECT_EQ(cdf.sample(0.5, {0.5, 0.5, 0.5}).pdf, 0.0) << what;
    EXPECT_EQ(cdf.pdf(glm::dvec3(1.0, -0.5, 2.0)), 0.0) << what;
    EXPECT_EQ(pack_gpu_emission_header(cdf).entry_count, 0u) << what;
  };
  DenseGrid zero = d;
  std::fill(zero.values.begin(), zero.values.end(), 0.0f);
  expect_empty(EmissionCdf::build(zero, &t, temperature_params()), "zero density");
  EmissionParams cold = temperature_params();
  cold.temperature.cutoff_k = 5000.0;  // every texel is below 2000 K
  expect_empty(EmissionCdf::build(d, &t, cold), "all below the cutoff");
  EmissionParams black = temperature_params();
  black.sigma_a = glm::dvec3(0.0);
  expect_empty(EmissionCdf::build(d, &t, black), "sigma_a 0");
  expect_empty(EmissionCdf::build(d, nullptr, temperature_params()), "no temperature grid");
  expect_empty(EmissionCdf::build(DenseGrid{}, &t, temperature_params()), "empty density grid");
  expect_empty(EmissionCdf{}, "default");
}

TEST(EmissionCdf, DemoFireWithItsSceneParameters) {
  const Scene scene = load_scene(std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/scenes/fire.json");
  ASSERT_FALSE(scene.media.empty());
  const Medium& m = scene.media[0];
  const StoredVolume vol = load_stored_volume(m);
  ASSERT_TRUE(vol.temperature);
  const EmissionCdf cdf = EmissionCdf::build(m, vol);
  ASSERT_FALSE(cdf.empty());
  std::printf("fire.vdb: %d x %d x %d cells (%zu), %zu emitting (%.1f %%), built in %.1f ms, power %.4g\n",
              cdf.cells().x, cdf.cells().y, cdf.cells().z, cdf.cell_count(), cdf.entry_count(),
              100.0 * cdf.entry_count() / cdf.cell_count(), 1e3 * cdf.seconds_to_build(), cdf.power());
  EXPECT_LT(cdf.entry_count(), cdf.cell_count());
  const DenseGrid& d = vol.density.grid;
  const DenseGrid& t = vol.temperature->grid;
  const EmissionParams p = EmissionParams::from_medium(m);

  // Chi-square on 8³-cell blocks against the summed pmf.
  const glm::ivec3 B = (cdf.cells() + 7) / 8;
  std::vector<double> expected(size_t(B.x) * B.y * B.z, 0.0), observed(expected.size(), 0.0);
  auto block = [&](glm::ivec3 c) { return (size_t(c.z / 8) * B.y + c.y / 8) * B.x + c.x / 8; };
  const int n = 400000;
  for (int k = 0; k < cdf.cells().z; ++k)
    for (int j = 0; j < cdf.cells().y; ++j)
      for (int i = 0; i < cdf.cells().x; ++i) expected[block({i, j, k})] += n * cdf.cell_pmf(cdf.linear_cell({i, j, k}));
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  std::vector<glm::dvec3> points;
  for (int k = 0; k < n; ++k) {
    EmissionSample s = cdf.sample(U(rng), {U(rng), U(rng), U(rng)});
    observed[block(cell_of(d, s.p))] += 1.0;
    if (k < 20000) points.push_back(s.p);
  }
  test::ChiSquareResult r = test::chi_square(observed, expected);
  std::printf("fire.vdb block chi-square: %s\n", r.summary().c_str());
  EXPECT_GT(r.p_value, 0.01) << r.summary();

  // Coverage near the emitting region: sampled points moved by up to ±2 cells
  // (into the blended fringe) still have pdf > 0 wherever they emit.
  int emitting = 0;
  for (const glm::dvec3& x0 : points) {
    const glm::dvec3 c = cdf.world_to_cell(x0) + 4.0 * glm::dvec3(U(rng) - 0.5, U(rng) - 0.5, U(rng) - 0.5);
    const glm::dvec3 x = cdf.cell_to_world(c);
    if (emitted_luminance(d, &t, p, x) > 0.0) {
      ++emitting;
      ASSERT_GT(cdf.pdf(x), 0.0) << c.x << " " << c.y << " " << c.z;
    }
  }
  EXPECT_GT(emitting, 10000);
}

// ---- blocks and direction pdfs (what next-event estimation samples; docs/mis.md) ----

namespace {

// ∫₀^∞ pdf(o + t·w) t² dt by the midpoint rule with step dt, independent of
// the DDA in direction_pdf. Only the chord through the world-space bounding
// box of the grid's corners is summed: the pdf is 0 outside the grid.
double direction_pdf_by_quadrature(const EmissionCdf& cdf, const glm::dvec3& o, const glm::dvec3& w, double dt) {
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 p = cdf.cell_to_world(glm::dvec3(cdf.cells()) * glm::dvec3(c & 1, (c >> 1) & 1, c >> 2));
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (w[a] == 0.0) {
      if (o[a] < lo[a] || o[a] > hi[a]) return 0.0;
      continue;
    }
    const double ta = (lo[a] - o[a]) / w[a], tb = (hi[a] - o[a]) / w[a];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  if (!(t0 < t1)) return 0.0;
  const int steps = int(std::ceil((t1 - t0) / dt));
  const double h = (t1 - t0) / steps;
  const double norm = cdf.receiver_norm(o);
  double sum = 0.0;
  for (int k = 0; k < steps; ++k) {
    const double t = t0 + (k + 0.5) * h;
    sum += cdf.pdf_from(o, norm, o + t * w) * t * t;
  }
  return sum * h;
}

glm::dvec3 uniform_direction(std::mt19937_64& rng) {
  std::uniform_real_distribution<double> U(0.0, 1.0);
  const double z = 2.0 * U(rng) - 1.0, phi = 2.0 * std::numbers::pi * U(rng), s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(phi), s * std::sin(phi), z};
}

}  // namespace

TEST(EmissionCdf, BlocksSumTheirCellsAndSampleUniformlyInside) {
  const DenseGrid d = random_density(11);
  const EmissionCdf cells = random_fire_cdf(d, 12);
  const EmissionCdf blocks = cells.blocks(3);
  ASSERT_FALSE(blocks.empty());
  EXPECT_EQ(blocks.cells(), (cells.cells() + 2) / 3);
  EXPECT_NEAR(blocks.cell_volume(), 27.0 * cells.cell_volume(), 1e-12);
  // Each block's probability is the sum of its cells'.
  std::vector<double> sum(blocks.cell_count(), 0.0);
  const glm::ivec3 C = cells.cells();
  for (int k = 0; k < C.z; ++k)
    for (int j = 0; j < C.y; ++j)
      for (int i = 0; i < C.x; ++i) {
        // The block that holds the cell's centre in world space.
        const glm::dvec3 centre = cells.cell_to_world(glm::dvec3(i, j, k) + 0.5);
        const glm::ivec3 b(glm::floor(blocks.world_to_cell(centre)));
        ASSERT_EQ(b, glm::ivec3(i / 3, j / 3, k / 3));
        sum[size_t(blocks.linear_cell(b))] += cells.cell_pmf(cells.linear_cell({i, j, k}));
      }
  double total = 0.0;
  for (size_t b = 0; b < sum.size(); ++b) {
    EXPECT_NEAR(blocks.cell_pmf(int64_t(b)), sum[b], 1e-6) << b;
    total += blocks.cell_pmf(int64_t(b));
  }
  EXPECT_NEAR(total, 1.0, 1e-5);
  // A sampled point lies in its block and has the pdf of that block.
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int n = 0; n < 5000; ++n) {
    const EmissionSample s = blocks.sample(U(rng), {U(rng), U(rng), U(rng)});
    ASSERT_GT(s.pdf, 0.0);
    EXPECT_NEAR(blocks.pdf(s.p), s.pdf, 1e-9 * s.pdf);
    EXPECT_NEAR(s.pdf, blocks.cell_pmf(s.cell) / blocks.cell_volume(), 1e-9 * s.pdf);
  }
  // The renderers' block size keeps every axis within kLightBlocksPerAxis.
  for (const glm::ivec3 c : {glm::ivec3(8, 7, 6), glm::ivec3(89, 135, 92), glm::ivec3(1000, 10, 10)}) {
    const int b = EmissionCdf::light_block(c);
    EXPECT_LE((std::max({c.x, c.y, c.z}) + b - 1) / b, EmissionCdf::kLightBlocksPerAxis) << b;
    EXPECT_TRUE(b == 1 || (std::max({c.x, c.y, c.z}) + b - 2) / (b - 1) > EmissionCdf::kLightBlocksPerAxis) << b;
  }
}

TEST(EmissionCdf, DirectionPdfIsTheIntegralAlongTheRay) {
  const DenseGrid d = random_density(14);
  const EmissionCdf fine = random_fire_cdf(d, 15);
  for (const EmissionCdf& cdf : {fine, fine.blocks(2), fine.blocks(2).clustered(2)}) {
    std::mt19937_64 rng(16);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const glm::dvec3 lo = cdf.cell_to_world(glm::dvec3(0.0)), hi = cdf.cell_to_world(glm::dvec3(cdf.cells()));
    const double extent = glm::length(hi - lo);
    // 64 rays per distribution, each a quadrature with steps of 3·10⁻⁶ of the
    // grid's diagonal over its chord (up to 3.3·10⁵ pdf lookups; under ASan,
    // tools/sanitize, about a second for the longest).
    int nonzero = 0;
    for (int n = 0; n < 64; ++n) {
      // Origins inside the grid (a scattering vertex in the fire) and outside.
      const EmissionSample s = cdf.sample(U(rng), {U(rng), U(rng), U(rng)});
      const glm::dvec3 w = uniform_direction(rng);
      const glm::dvec3 o = n % 2 ? s.p : s.p - 1.5 * extent * w;
      const double dda = cdf.direction_pdf(o, w);
      const double quad = direction_pdf_by_quadrature(cdf, o, w, 3e-6 * extent);
      EXPECT_NEAR(dda, quad, 2e-3 * quad + 1e-9) << n;
      nonzero += dda > 0.0;
    }
    EXPECT_GT(nonzero, 48);
  }
}

TEST(EmissionCdf, DirectionPdfIntegratesToOneOverTheSphere) {
  const DenseGrid d = random_density(17);
  const EmissionCdf fine = random_fire_cdf(d, 18);
  const EmissionCdf blocks = fine.blocks(3);
  const EmissionCdf clusters = fine.clustered(3);
  for (const EmissionCdf* cdf : {&fine, &blocks, &clusters}) {
    const glm::dvec3 centre = cdf->cell_to_world(glm::dvec3(cdf->cells()) * 0.5);
    double radius = 0.0;  // of a sphere around the blocks
    for (int c = 0; c < 8; ++c)
      radius = std::max(radius, glm::length(cdf->cell_to_world(glm::dvec3(cdf->cells()) *
                                                               glm::dvec3(c & 1, (c >> 1) & 1, c >> 2)) - centre));
    const glm::dvec3 far = centre + glm::dvec3(2.0, -1.0, 0.5) * radius;
    for (const glm::dvec3& o : {centre, far}) {
      // ∫ p(ω) dω = E[p(ω)/q(ω)] for ω from q: uniform on the sphere from
      // inside, uniform in the cone around the bounding sphere from outside.
      const double dist = glm::length(centre - o);
      const bool cone = dist > radius;
      const double cos_max = cone ? std::sqrt(1.0 - radius * radius / (dist * dist)) : -1.0;
      const glm::dvec3 axis = cone ? (centre - o) / dist : glm::dvec3(0, 0, 1);
      const glm::dvec3 tx = glm::normalize(glm::cross(axis, std::abs(axis.x) < 0.9 ? glm::dvec3(1, 0, 0) : glm::dvec3(0, 1, 0)));
      const glm::dvec3 ty = glm::cross(axis, tx);
      const double q = 1.0 / (2.0 * std::numbers::pi * (1.0 - cos_max));
      std::mt19937_64 rng(19);
      std::uniform_real_distribution<double> U(0.0, 1.0);
      const int n = 200000;
      double sum = 0.0, sq = 0.0;
      for (int k = 0; k < n; ++k) {
        const double z = 1.0 - U(rng) * (1.0 - cos_max), phi = 2.0 * std::numbers::pi * U(rng);
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const glm::dvec3 w = z * axis + r * std::cos(phi) * tx + r * std::sin(phi) * ty;
        const double x = cdf->direction_pdf(o, w) / q;
        sum += x;
        sq += x * x;
      }
      const double mean = sum / n, se = std::sqrt(std::max(0.0, sq / n - mean * mean) / n);
      std::printf("∫ direction pdf dω = %.5f ± %.5f\n", mean, se);
      EXPECT_LT(std::abs(mean - 1.0), 4.0 * se + 1e-6);
      EXPECT_LT(se, 0.02);  // the test has the power to see a 10 % error
    }
  }
}

// Seen from a receiver (clustered): the sampler follows pdf_from (chi-square
// over the cells), pdf_from integrates to 1, nearby clusters gain, and from far
// away the distribution tends to the static one (all clusters at about the
// same distance).
TEST(EmissionCdf, ClustersSeenFromAReceiver) {
  const DenseGrid d = random_density(21);
  const EmissionCdf fine = random_fire_cdf(d, 22);
  const EmissionCdf cdf = fine.clustered(3);
  ASSERT_TRUE(cdf.is_clustered());
  ASSERT_FALSE(fine.is_clustered());
  const glm::ivec3 C = cdf.cells();
  const glm::dvec3 corner = cdf.cell_to_world(glm::dvec3(0.0)), centre = cdf.cell_to_world(glm::dvec3(C) * 0.5);
  const double extent = glm::length(cdf.cell_to_world(glm::dvec3(C)) - corner);
  auto cell_centre = [&](int64_t c) {
    return cdf.cell_to_world(glm::dvec3(c % C.x, (c / C.x) % C.y, c / (int64_t(C.x) * C.y)) + 0.5);
  };
  for (const glm::dvec3& o : {corner, centre, centre + glm::dvec3(0.3, -0.2, 1.1) * extent}) {
    // Σ pdf_from · volume = 1 over the cells.
    std::vector<double> p(cdf.cell_count());
    double total = 0.0;
    for (size_t c = 0; c < p.size(); ++c) total += p[c] = cdf.pdf_from(o, cell_centre(int64_t(c))) * cdf.cell_volume();
    EXPECT_NEAR(total, 1.0, 1e-5);
    // The sampled cells follow p; each sample's pdf is pdf_from of its point.
    std::mt19937_64 rng(23);
    std::uniform_real_distribution<double> U(0.0, 1.0);
    const int n = 200000;
    std::vector<double> observed(p.size(), 0.0), expected(p.size());
    for (size_t c = 0; c < p.size(); ++c) expected[c] = n * p[c];
    const double norm = cdf.receiver_norm(o);
    for (int k = 0; k < n; ++k) {
      const EmissionSample s = cdf.sample_from(o, norm, U(rng), U(rng), {U(rng), U(rng), U(rng)});
      ASSERT_GT(s.pdf, 0.0);
      ASSERT_NEAR(s.pdf, cdf.pdf_from(o, s.p), 1e-9 * s.pdf) << k;
      observed[size_t(s.cell)] += 1.0;
    }
    const test::ChiSquareResult r = test::chi_square(observed, expected);
    std::printf("clustered emission CDF chi-square: %s\n", r.summary().c_str());
    EXPECT_GT(r.p_value, 0.01) << r.summary();
  }
  // Next to a corner, the cells there are likelier than in the static distribution.
  const glm::dvec3 near_corner = cdf.cell_to_world(glm::dvec3(0.5));
  double near_static = 0.0, near_receiver = 0.0;
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i) {
        const glm::dvec3 x = cdf.cell_to_world(glm::dvec3(i, j, k) + 0.5);
        near_static += fine.pdf(x);
        near_receiver += cdf.pdf_from(near_corner, x);
      }
  ASSERT_GT(near_static, 0.0);
  EXPECT_GT(near_receiver, 2.0 * near_static);
  // Far away, pdf_from / pdf → 1 (to within the spread of 1/d² over the grid).
  const glm::dvec3 far = centre + glm::dvec3(0.0, 0.0, 1000.0 * extent);
  for (size_t c = 0; c < cdf.cell_count(); ++c) {
    const glm::dvec3 x = cell_centre(int64_t(c));
    if (fine.pdf(x) > 0.0) EXPECT_NEAR(cdf.pdf_from(far, x) / fine.pdf(x), 1.0, 1e-2) << c;
  }
}
