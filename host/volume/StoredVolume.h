#pragma once
// A vdb medium's grids as the renderers store them: the dense values rounded to
// the texture format the GPU samples (R16F by default), so the CPU reference, the
// majorant grid and the GPU all see exactly the same numbers. Computing majorants
// from unrounded floats lets the texture exceed its bound (pbrt-v4 issue 33).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "volume/DenseGrid.h"
#include "volume/VolumeOptions.h"

namespace pyrolume {

struct StoredGrid {
  DenseGrid grid;                // values as stored (already rounded when R16F)
  TextureFormat format = TextureFormat::R16F;  // Sparse: grid.sparse holds the values
  std::vector<uint16_t> half_bits;  // the R16F texels to upload (empty for R32F)
};

struct StoredVolume {
  StoredGrid density;
  std::optional<StoredGrid> temperature;  // only when the medium emits from its temperature
  std::vector<std::string> warnings;
};

// Loads the grids (VdbLoader) and rounds them to their texture format:
// options.texture_format, promoted to R32F when a stored value exceeds what
// R16F holds (|v| > 6e4). A Medium's: scene/MediumVolume.h.
StoredVolume load_stored_volume(const VolumeOptions& options, const DenseLimits& limits = {});

// "" when the temperature grid's hottest value maps above the cutoff;
// otherwise the warning (naming the grid, the hottest temperature and a fix
// that changes the image: a temperature.scale other than the one in use, or,
// for a constant grid, that there is no fire to show) that load_stored_volume adds.
std::string cold_temperature_warning(const DenseGrid& temperature, const TemperatureMapping& mapping);

// Rounds every value to the nearest half and fills half_bits.
void round_to_format(StoredGrid& g);

}  // namespace pyrolume
