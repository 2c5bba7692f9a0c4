#include "volume/StoredVolume.h"

#include <cmath>
#include <cstdio>

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

std::string cold_temperature_warning(const DenseGrid& t, const TemperatureMapping& map) {
  const double hottest_value = map.hottest_value(t.min_value, t.max_value);
  const double hottest_k = map.kelvin(hottest_value);
  if (!(hottest_k <= map.cutoff_k)) return "";  // something glows (NaN-safe)
  char line[512];
  std::snprintf(line, sizeof line,
                "temperature grid \"%s\": the hottest voxel maps to %.4g K, at or below temperature.cutoff_k %.4g K, so "
                "nothing glows",
                t.name.c_str(), hottest_k, map.cutoff_k);
  std::string w = line;
  // A constant grid (an all-zero flame grid) has no temperature to map: no
  // scale or offset shows a fire that is not there.
  if (t.min_value == t.max_value) {
    std::snprintf(line, sizeof line, "; every voxel holds %.4g, so the file has no fire here (leave out the emission and "
                  "temperature keys to render it as smoke)", double(t.max_value));
    return w + line;
  }
  // The scale that puts the hottest voxel above the cutoff (1500 K, a visible
  // fire, or 1.5 × a higher cutoff): never the scale already in use.
  const double target_k = std::max(1500.0, 1.5 * map.cutoff_k);
  if (hottest_value - map.offset > 0.0) {
    std::snprintf(line, sizeof line, "; temperature.scale %.4g would put it at %.4g K",
                  target_k / (hottest_value - map.offset), target_k);
    w += line;
  } else {
    std::snprintf(line, sizeof line, "; its values are at or below temperature.offset %.4g: lower the offset",
                  map.offset);
    w += line;
  }
  return w;
}

}  // namespace pyrolume
