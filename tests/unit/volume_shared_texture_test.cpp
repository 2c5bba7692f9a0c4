// Density and temperature in one two-channel texture (GpuScene
// temperature_in_density): when it is allowed, and that every density texel
// gets the temperature texel at the same index (0 outside the temperature's box).
#include <glm/gtc/packing.hpp>
#include <gtest/gtest.h>

#include "render/vulkan/GpuScene.h"
#include "volume/StoredVolume.h"

namespace pyrolume {
namespace {

// A grid on the lattice world = 0.1 · index, texels origin .. origin + dims − 1,
// texel value `base + index · (1, 10, 100)` (distinct everywhere), stored as
// `format`.
StoredGrid grid(glm::ivec3 origin, glm::ivec3 dims, float base, TextureFormat format, double voxel = 0.1) {
  StoredGrid g;
  g.format = format;
  g.grid.origin = origin;
  g.grid.dims = dims;
  g.grid.index_to_world = glm::dmat4(voxel);
  g.grid.index_to_world[3][3] = 1.0;
  g.grid.world_to_index = glm::inverse(g.grid.index_to_world);
  for (int k = 0; k < dims.z; ++k)
    for (int j = 0; j < dims.y; ++j)
      for (int i = 0; i < dims.x; ++i) {
        const glm::ivec3 ijk = origin + glm::ivec3(i, j, k);
        g.grid.values.push_back(base + float(ijk.x + 10 * ijk.y + 100 * ijk.z));
      }
  round_to_format(g);
  return g;
}

TEST(SharedTexture, OnlyForOneIndexSpaceAndAtMostAQuarterMoreMemory) {
  const StoredGrid density = grid({0, 0, 0}, {10, 10, 10}, 0.f, TextureFormat::R16F);
  const uint64_t any = ~uint64_t(0);
  EXPECT_TRUE(temperature_fits_density_texture(density, grid({0, 0, 0}, {10, 10, 10}, 5.f, TextureFormat::R16F), any));
  // Another voxel size: another lattice.
  EXPECT_FALSE(temperature_fits_density_texture(
      density, grid({0, 0, 0}, {10, 10, 10}, 5.f, TextureFormat::R16F, 0.2), any));
  // A small temperature box: RG over the density's box would cost 2000 texels
  // of halves against 1000 + 216 apart.
  EXPECT_FALSE(temperature_fits_density_texture(density, grid({2, 2, 2}, {6, 6, 6}, 5.f, TextureFormat::R16F), any));
  EXPECT_TRUE(temperature_fits_density_texture(density, grid({1, 0, 0}, {9, 10, 10}, 5.f, TextureFormat::R16F), any));
  // The device's allocation limit (and the test hook's 0).
  EXPECT_FALSE(temperature_fits_density_texture(density, grid({0, 0, 0}, {10, 10, 10}, 5.f, TextureFormat::R16F),
                                                2 * 2 * 1000 - 1));
  EXPECT_FALSE(temperature_fits_density_texture(density, grid({0, 0, 0}, {10, 10, 10}, 5.f, TextureFormat::R16F), 0));
  // An R32F temperature makes the pair RG32F: 8000 bytes against 2000 + 4000.
  EXPECT_FALSE(temperature_fits_density_texture(density, grid({0, 0, 0}, {10, 10, 10}, 5.f, TextureFormat::R32F), any));
  const StoredGrid density32 = grid({0, 0, 0}, {10, 10, 10}, 0.f, TextureFormat::R32F);
  EXPECT_TRUE(
      temperature_fits_density_texture(density32, grid({0, 0, 0}, {10, 10, 10}, 5.f, TextureFormat::R32F), any));
}

// Each density texel (i, j, k) is index origin + (i, j, k); its second channel
// is the temperature at that index, or 0 outside the temperature's texels.
void expect_interleaved(const StoredGrid& density, const StoredGrid& temperature) {
  const DensityTemperatureTexels t = density_temperature_texels(density, temperature);
  const bool half = density.format == TextureFormat::R16F && temperature.format == TextureFormat::R16F;
  ASSERT_EQ(t.half, half);
  const DenseGrid& d = density.grid;
  ASSERT_EQ((half ? t.half_bits.size() : t.values.size()), 2 * d.texel_count());
  int inside = 0, outside = 0;
  size_t at = 0;
  for (int k = 0; k < d.dims.z; ++k)
    for (int j = 0; j < d.dims.y; ++j)
      for (int i = 0; i < d.dims.x; ++i, ++at) {
        const glm::ivec3 index = d.origin + glm::ivec3(i, j, k);
        const glm::ivec3 ti = index - temperature.grid.origin;
        const bool in = glm::all(glm::greaterThanEqual(ti, glm::ivec3(0))) &&
                        glm::all(glm::lessThan(ti, temperature.grid.dims));
        const float want_t = in ? temperature.grid.texel(ti.x, ti.y, ti.z) : 0.f;
        const float got_d = half ? glm::unpackHalf1x16(t.half_bits[2 * at]) : t.values[2 * at];
        const float got_t = half ? glm::unpackHalf1x16(t.half_bits[2 * at + 1]) : t.values[2 * at + 1];
        ASSERT_EQ(got_d, d.texel(i, j, k)) << "density texel " << i << "," << j << "," << k;
        ASSERT_EQ(got_t, want_t) << "temperature at density texel " << i << "," << j << "," << k;
        (in ? inside : outside) += 1;
      }
  EXPECT_GT(inside, 0);
  EXPECT_GT(outside, 0);
}

TEST(SharedTexture, EveryDensityTexelGetsTheTemperatureAtItsIndex) {
  // The temperature's box sticks out of the density's on some sides and stops
  // short on others.
  expect_interleaved(grid({-3, 2, 0}, {8, 5, 6}, 0.f, TextureFormat::R16F),
                     grid({-1, 0, 2}, {9, 6, 3}, 7.f, TextureFormat::R16F));
  expect_interleaved(grid({-3, 2, 0}, {8, 5, 6}, 0.f, TextureFormat::R32F),
                     grid({-1, 0, 2}, {9, 6, 3}, 7.f, TextureFormat::R16F));
}

}  // namespace
}  // namespace pyrolume
