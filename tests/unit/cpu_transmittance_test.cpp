// Ratio- and delta-tracking transmittance of the CPU reference (issue 5 part 4)
// against exp(−∫σt) through grids whose optical depth is known independently.
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "render/cpu/Transmittance.h"
#include "support/AnalyticScenes.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "volume/StoredVolume.h"

namespace pyrolume {
namespace {

using cpu::MediaData;
using cpu::Pcg32;
using cpu::TrackingCounters;

struct Estimate {
  double mean = 0.0, se = 0.0;
  double zero_fraction = 0.0;  // estimates that came back exactly 0
  uint64_t lookups = 0, violations = 0;
};

enum class Tracker { Ratio, Delta };

Estimate estimate(const MediaData& md, Tracker tracker, int c, glm::dvec3 o, glm::dvec3 d, double t_max, int n,
                  uint64_t seed) {
  Pcg32 rng(seed, 0x9e3779b9ull + seed);
  TrackingCounters cnt;
  double sum = 0.0, sum_sq = 0.0;
  int zeros = 0;
  d = glm::normalize(d);
  for (int i = 0; i < n; ++i) {
    const double T = tracker == Tracker::Ratio ? cpu::ratio_tracking_transmittance(md, c, o, d, t_max, rng, &cnt)
                                               : cpu::delta_tracking_transmittance(md, c, o, d, t_max, rng, &cnt);
    sum += T;
    sum_sq += T * T;
    zeros += T == 0.0;
  }
  Estimate e;
  e.mean = sum / n;
  e.se = std::sqrt(std::max(0.0, sum_sq / n - e.mean * e.mean) / (n - 1));
  e.zero_fraction = double(zeros) / n;
  e.lookups = cnt.density_lookups;
  e.violations = cnt.majorant_violations;
  return e;
}

// Both trackers agree with `expected` within 4σ, and σ is small enough for
// that to mean something (<= 1 % of the value, or 1e-3 absolute).
void expect_transmittance(const MediaData& md, int c, glm::dvec3 o, glm::dvec3 d, double t_max, double expected,
                          int n, const std::string& what) {
  for (Tracker tr : {Tracker::Ratio, Tracker::Delta}) {
    const char* name = tr == Tracker::Ratio ? "ratio" : "delta";
    Estimate e = estimate(md, tr, c, o, d, t_max, n, tr == Tracker::Ratio ? 11 : 23);
    std::printf("%s %s c%d: %.6f ± %.6f (SE), exact %.6f, z %+.2f, zeros %.3f, lookups/est %.2f\n", what.c_str(),
                name, c, e.mean, e.se, expected, (e.mean - expected) / e.se, e.zero_fraction,
                double(e.lookups) / n);
    EXPECT_LE(std::abs(e.mean - expected), 4.0 * e.se) << what << " " << name << " c" << c;
    EXPECT_LE(e.se, std::max(0.01 * expected, 1e-3)) << what << " " << name << ": not informative";
    EXPECT_EQ(e.violations, 0u) << what << " " << name;
    EXPECT_GT(e.lookups, 0u) << what << " " << name;
  }
}

class Transmittance : public ::testing::Test {
 protected:
  std::filesystem::path dir = test::temp_dir("cpu_transmittance");
};

// ρ = a + b·i on voxels i = 0..20 (a, b and every value exact in half).
// Trilinear interpolation reproduces a linear field exactly, so inside the
// centre box ρ(p) = a + b·u_x(p) and ∫σt along a segment there is
//   σt · length · (a + b · (u_x(p0) + u_x(p1))/2)   (mean of a linear function).
TEST_F(Transmittance, DensityRampMatchesClosedForm) {
  const test::RampX ramp;
  const double a = ramp.a, b = ramp.b;
  const test::Lattice& lat = ramp.lat;
  Scene s = test::vdb_base_scene(8, 8, 1);
  s.media.push_back(ramp.medium(dir, {0.3, 0.8, 1.2}, {0.2, 0.2, 0.3}));
  const MediaData md = cpu::prepare_media(s);
  ASSERT_EQ(md.media.size(), 1u);
  ASSERT_DOUBLE_EQ(md.media[0].max_density, a + 20 * b);

  struct Seg {
    glm::dvec3 p0, p1;
  };
  // Along x (the ramp's axis) and obliquely, both within the centre box.
  const Seg segs[] = {{{0.05, 0.013, -0.021}, {1.95, 0.013, -0.021}}, {{0.1, -0.3, -0.2}, {1.8, 0.35, 0.4}}};
  for (const Seg& sg : segs)
    for (int c = 0; c < 3; ++c) {
      const double sigma_t = s.media[0].sigma_a[c] + s.media[0].sigma_s[c];
      const double len = glm::length(sg.p1 - sg.p0);
      const double tau = sigma_t * len * (a + b * 0.5 * (lat.index(sg.p0).x + lat.index(sg.p1).x));
      expect_transmittance(md, c, sg.p0, sg.p1 - sg.p0, len, std::exp(-tau), 200000, "ramp");
    }
}

// The checkerboard's trilinear field has no simple closed form across cells, so
// ∫ρ is computed by quadrature of the SAME stored field the renderer samples
// (DenseGrid::sample_world): along a ray, between crossings of the index
// lattice planes (texel centres), trilinear interpolation is a product of three
// linear functions of t, a cubic, which 3-point Gauss–Legendre integrates
// exactly. The reference thus shares only the texture lookup with the tracker
// (checked against OpenVDB's BoxSampler in volume_loader_test), not the
// majorant, the free-flight sampling or the estimator.
double checker_optical_depth(const DenseGrid& g, glm::dvec3 o, glm::dvec3 d, double t_max) {
  d = glm::normalize(d);
  glm::dvec3 lo, hi;
  g.world_bounds(lo, hi);
  const glm::dvec3 uo(g.world_to_index * glm::dvec4(o, 1.0)), ud(g.world_to_index * glm::dvec4(d, 0.0));
  std::vector<double> ts{0.0, t_max};
  for (int a = 0; a < 3; ++a) {
    if (ud[a] == 0.0) continue;
    for (int k = g.origin[a]; k <= g.origin[a] + g.dims[a] - 1; ++k) {
      const double t = (k - uo[a]) / ud[a];
      if (t > 0.0 && t < t_max) ts.push_back(t);
    }
  }
  std::sort(ts.begin(), ts.end());
  const double x[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, w[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  double sum = 0.0;
  for (size_t i = 0; i + 1 < ts.size(); ++i) {
    const double m = 0.5 * (ts[i] + ts[i + 1]), h = 0.5 * (ts[i + 1] - ts[i]);
    for (int q = 0; q < 3; ++q) sum += w[q] * h * g.sample_world(o + (m + h * x[q]) * d);
  }
  return sum;
}

TEST_F(Transmittance, CheckerboardMatchesQuadratureOfTheSameField) {
  const test::Lattice lat{0.1, {0.03, -0.02, 0.01}};
  const test::VoxelBox box{{-6, -5, -4}, {6, 5, 7}};
  Scene s = test::vdb_base_scene(8, 8, 1);
  s.media.push_back(test::vdb_medium(
      "checker", test::write_checkerboard_vdb(dir / "checker.vdb", lat, box, 0.25f, 2.0f), {0.6, 1.5, 3.0},
      {0.4, 0.5, 1.0}));
  const MediaData md = cpu::prepare_media(s);
  const DenseGrid& g = md.media[0].volume->density.grid;
  // Through the whole grid from outside (edge ramps included), obliquely, and
  // ending inside the grid.
  struct Ray {
    glm::dvec3 o, d;
    double t_max;
  };
  const Ray rays[] = {{{-1.0, 0.02, 0.1}, {1.0, 0.05, -0.03}, INFINITY},
                      {{-0.7, -0.8, -0.6}, {0.8, 0.9, 1.0}, INFINITY},
                      {{0.5, 0.6, -1.0}, {-0.3, -0.4, 1.0}, 1.2}};
  for (const Ray& r : rays)
    for (int c = 0; c < 3; ++c) {
      const double sigma_t = s.media[0].sigma_a[c] + s.media[0].sigma_s[c];
      const double tau = sigma_t * checker_optical_depth(g, r.o, r.d, std::isfinite(r.t_max) ? r.t_max : 1e3);
      expect_transmittance(md, c, r.o, r.d, r.t_max, std::exp(-tau), 200000, "checker");
    }
}

// Optical depth ~4: the running ratio-tracking estimate falls below 0.1 on
// almost every path, so Russian roulette decides most of the result; it must
// stay unbiased (and actually happen: many estimates are exactly 0).
TEST_F(Transmittance, RussianRouletteKeepsRatioTrackingUnbiased) {
  const test::RampX ramp;
  const double a = ramp.a, b = ramp.b;
  Scene s = test::vdb_base_scene(8, 8, 1);
  s.media.push_back(ramp.medium(dir, {1.2, 1.2, 1.2}, {0.0, 0.0, 0.0}));
  const MediaData md = cpu::prepare_media(s);
  const glm::dvec3 p0(0.05, 0.0, 0.0), p1(1.95, 0.0, 0.0);
  const double tau = 1.2 * 1.9 * (a + b * 0.5 * (0.5 + 19.5));  // ≈ 4, T ≈ 0.0185
  const double expected = std::exp(-tau);
  Estimate e = estimate(md, Tracker::Ratio, 0, p0, p1 - p0, 1.9, 400000, 5);
  std::printf("roulette: %.6g ± %.3g vs %.6g, zeros %.3f\n", e.mean, e.se, expected, e.zero_fraction);
  EXPECT_LE(std::abs(e.mean - expected), 4.0 * e.se);
  EXPECT_LE(e.se, 0.02 * expected);
  EXPECT_GT(e.zero_fraction, 0.5);  // roulette really ran
}

// A homogeneous box overlapping the grid: the coefficients add, and so do the
// majorants of the segment where both are present.
TEST_F(Transmittance, HomogeneousAndGridMediaAdd) {
  const test::RampX ramp;
  const double a = ramp.a, b = ramp.b;
  Scene s = test::vdb_base_scene(8, 8, 1);
  s.media.push_back(ramp.medium(dir, {0.4, 0.4, 0.4}, {0.1, 0.1, 0.1}));
  s.media.push_back(test::homogeneous_box("slab", {1.0, -1.0, -1.0}, {3.0, 1.0, 1.0}, {0.7, 0.7, 0.7},
                                          {0.2, 0.2, 0.2}, 0.0, std::nullopt));
  const MediaData md = cpu::prepare_media(s);
  // From x = 0.05 (inside the ramp's centre box) to x = 2.5: the grid's part
  // ends at its centre box x = 2.0 plus one voxel of linear fall-off to 0
  // (∫ over it = 0.5 voxel · ρ(20) for a ray along x); the slab covers 1.0 .. 2.5.
  const glm::dvec3 p0(0.05, 0.0, 0.0), p1(2.5, 0.0, 0.0);
  const double grid_int = 1.95 * (a + b * 0.5 * (0.5 + 20.0)) + 0.5 * 0.1 * (a + 20 * b);
  const double tau = 0.5 * grid_int + 0.9 * 1.5;
  expect_transmittance(md, 0, p0, p1 - p0, 2.45, std::exp(-tau), 200000, "overlap");
}

TEST_F(Transmittance, EmptyAndZeroGridsAndMissesTransmitEverything) {
  Scene s = test::vdb_base_scene(8, 8, 1);
  test::add_empty_and_zero_grids(s, dir);
  const MediaData md = cpu::prepare_media(s);
  Pcg32 rng(1, 2);
  for (int i = 0; i < 100; ++i) {
    EXPECT_EQ(cpu::ratio_tracking_transmittance(md, 0, {-1, 0, 0}, {1, 0, 0}, INFINITY, rng), 1.0);
    EXPECT_EQ(cpu::delta_tracking_transmittance(md, 0, {-1, 0, 0}, {1, 0, 0}, INFINITY, rng), 1.0);
  }
}

}  // namespace
}  // namespace pyrolume
