#include "volume/StoredVolume.h"

#include <cmath>

#include <glm/gtc/packing.hpp>

#include "volume/VdbLoader.h"

namespace pyrolume {

void round_to_format(StoredGrid& g) {
  g.half_bits.clear();
  if (g.format != TextureFormat::R16F) return;
  g.half_bits.resize(g.grid.values.size());
  for (size_t i = 0; i < g.grid.values.size(); ++i) {
    g.half_bits[i] = glm::packHalf1x16(g.grid.values[i]);
    g.grid.values[i] = glm::unpackHalf1x16(g.half_bits[i]);
  }
  if (!g.grid.values.empty()) {
    g.grid.min_value = glm::unpackHalf1x16(glm::packHalf1x16(g.grid.min_value));
    g.grid.max_value = glm::unpackHalf1x16(glm::packHalf1x16(g.grid.max_value));
  }
}

namespace {
StoredGrid store(DenseGrid grid, TextureFormat wanted) {
  StoredGrid g;
  if (grid.is_sparse()) {  // floats in the tree, as the GPU reads them
    g.format = TextureFormat::Sparse;
    g.grid = std::move(grid);
    return g;
  }
  // R16F's largest finite value is 65504; keep a margin for rounding.
  bool fits_half = std::max(std::abs(grid.min_value), std::abs(grid.max_value)) <= 6.0e4f;
  g.format = (wanted != TextureFormat::R32F && fits_half) ? TextureFormat::R16F : TextureFormat::R32F;
  g.grid = std::move(grid);
  round_to_format(g);
  return g;
}
}  // namespace

StoredVolume load_stored_volume(const VolumeOptions& m, const DenseLimits& limits) {
  VolumeGrids grids = load_volume(m, limits);
  const TextureFormat wanted = m.texture_format;
  StoredVolume v;
  v.density = store(std::move(grids.density), wanted);
  if (grids.temperature) v.temperature = store(std::move(*grids.temperature), wanted);
  v.warnings = std::move(grids.warnings);
  // A mapping under which nothing glows is almost always a missing scale.
  if (v.temperature && !v.temperature->grid.empty())
    if (const std::string w = cold_temperature_warning(v.temperature->grid, m.temperature); !w.empty())
      v.warnings.push_back(m.file.string() + ": " + w);
  return v;
}

}  // namespace pyrolume
