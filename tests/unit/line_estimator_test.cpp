// Which media the line estimator collects and at what rates
// (host/render/LineEstimator.h, docs/rendering.md "The line estimator"): thin
// against dense grids and homogeneous media, the power share that leaves a
// faint thin medium to the collision estimator, the file's explicit choice,
// and the per-cell rates.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "render/LineEstimator.h"
#include "scene/Scene.h"
#include "support/AnalyticScenes.h"
#include "volume/MajorantGrid.h"
#include "volume/StoredVolume.h"

namespace pyrolume {
namespace {

// A 32³ block of density 1 (voxels of 0.1: 3.2 units across) inside a 34³
// texture with its zero padding, emitting a constant rgb.
StoredVolume block_volume() {
  StoredVolume v;
  DenseGrid& g = v.density.grid;
  g.dims = glm::ivec3(34);
  g.origin = glm::ivec3(-1);
  g.index_to_world = glm::dmat4(0.1);
  g.index_to_world[3] = glm::dvec4(0.0, 0.0, 0.0, 1.0);
  g.world_to_index = glm::inverse(g.index_to_world);
  g.values.assign(g.texel_count(), 0.0f);
  for (int k = 1; k < 33; ++k)
    for (int j = 1; j < 33; ++j)
      for (int i = 1; i < 33; ++i) g.values[(size_t(k) * 34 + j) * 34 + i] = 1.0f;
  g.min_value = g.max_value = 1.0f;
  return v;
}

Medium block_medium(double density_scale, double emission_scale) {
  Medium m;
  m.name = "block";
  m.type = Medium::Type::Vdb;
  m.sigma_a = glm::dvec3(1.0);
  m.sigma_s = glm::dvec3(0.5);
  m.density_scale = density_scale;
  m.emission.rgb = glm::dvec3(1.0, 0.5, 0.25);
  m.emission.scale = emission_scale;
  return m;
}

Scene scene_of(std::vector<Medium> media) {
  Scene s = test::analytic_base_scene(8, 8, 1);
  s.media = std::move(media);
  return s;
}

// σt·3.2 = 4.8 collisions across the dense block, 0.048 across the thin one.
TEST(LineEstimator, ThinGridsAreCollectedByTheLineEstimatorAndDenseOnesAreNot) {
  const StoredVolume v = block_volume();
  EXPECT_EQ(line_media(scene_of({block_medium(1.0, 1.0)}), {&v}).line, std::vector<bool>{false});
  EXPECT_EQ(line_media(scene_of({block_medium(0.01, 100.0)}), {&v}).line, std::vector<bool>{true});
  // Without emission there is nothing to collect.
  Medium dark = block_medium(0.01, 100.0);
  dark.emission = Emission{};
  EXPECT_EQ(line_media(scene_of({dark}), {&v}).line, std::vector<bool>{false});
}

TEST(LineEstimator, CollisionsAcrossAreTheMajorantTimesTheEmissionsDepth) {
  const StoredVolume v = block_volume();
  const MajorantGrid mg = build_majorant_grid(v.density.grid, glm::ivec3(4));
  const LineRates r = line_rates(block_medium(0.01, 100.0), v.density.grid, nullptr, mg);
  // σ̄ = 1.5 · 0.01 in every cell; the emissive cells span the whole texture, 3.4 units.
  EXPECT_NEAR(r.collisions_across, 0.015 * 3.4, 1e-6);
  EXPECT_TRUE(r.thin());
  // kLinePointsPerCell per cell width (8.5 texels of 0.1) in every cell that can emit: all 64 here.
  ASSERT_EQ(r.rate.size(), 64u);
  for (float rate : r.rate) EXPECT_NEAR(rate, kLinePointsPerCell / 0.85, 1e-4);
  EXPECT_GT(r.power, 0.0);
}

TEST(LineEstimator, AFaintThinMediumBesideABrightOneIsLeftToCollisions) {
  const StoredVolume v = block_volume();
  // A thin homogeneous sphere: σt·2r = 0.02.
  const Medium bright = test::homogeneous_sphere("bright", {5, 0, 0}, 1.0, glm::dvec3(0.01), glm::dvec3(0.0), 0.0,
                                                 glm::dvec3(1.0), 1000.0);
  // The thin block emits 1/1000 of the sphere's power: not worth its points.
  EXPECT_EQ(line_media(scene_of({bright, block_medium(0.01, 0.1)}), {nullptr, &v}).line, (std::vector<bool>{true, false}));
  // About as bright as the sphere (Y(σa·Le)·volume: 42 against 32): both.
  EXPECT_EQ(line_media(scene_of({bright, block_medium(0.01, 150.0)}), {nullptr, &v}).line,
            (std::vector<bool>{true, true}));
}

TEST(LineEstimator, HomogeneousMediaAreThinBelowTwoCollisionsAcross) {
  auto sphere = [](double sigma_t) {
    return test::homogeneous_sphere("s", {0, 0, 0}, 0.5, glm::dvec3(sigma_t), glm::dvec3(0.0), 0.0, glm::dvec3(1.0));
  };
  EXPECT_TRUE(homogeneous_emission_is_thin(sphere(1.9)));  // 1.9 collisions across its diameter
  EXPECT_FALSE(homogeneous_emission_is_thin(sphere(2.1)));
  // A slab is as thin as its thinnest side.
  const Medium slab = test::homogeneous_box("slab", {-4, -4, -0.05}, {4, 4, 0.05}, glm::dvec3(10.0), glm::dvec3(0.0),
                                            0.0, glm::dvec3(1.0));
  EXPECT_TRUE(homogeneous_emission_is_thin(slab));
  Medium dark = sphere(0.1);
  dark.emission = Emission{};
  EXPECT_FALSE(homogeneous_emission_is_thin(dark));
}

TEST(LineEstimator, TheFilesChoiceWins) {
  const StoredVolume v = block_volume();
  Scene dense = scene_of({block_medium(1.0, 1.0)});
  dense.integrator.emission_estimator = EmissionEstimator::Line;
  EXPECT_EQ(line_media(dense, {&v}).line, std::vector<bool>{true});
  Scene thin = scene_of({block_medium(0.01, 100.0)});
  for (EmissionEstimator e : {EmissionEstimator::Collision, EmissionEstimator::Absorption}) {
    thin.integrator.emission_estimator = e;
    EXPECT_EQ(line_media(thin, {&v}).line, std::vector<bool>{false}) << to_string(e);
  }
}

}  // namespace
}  // namespace pyrolume
