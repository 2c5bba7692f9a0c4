#pragma once
// Loads the grids a `type: vdb` medium names from an OpenVDB (.vdb) or NanoVDB
// (.nvdb) file into dense arrays (docs/volumes.md).
#include <cstdint>

#include <glm/glm.hpp>

#include "volume/DenseGrid.h"
#include "volume/VolumeOptions.h"

namespace pyrolume {

// Names tried, in order, when a medium gives no temperature_grid.
inline constexpr const char* kDefaultTemperatureGrids[] = {"temperature", "heat", "flame"};
inline constexpr const char* kDefaultDensityGrid = "density";

// Reads only the density grid (and, when options.need_temperature, the
// temperature grid) named in options, each into its own DenseGrid with its own
// index->world map, options.transform composed on top. A Medium's:
// scene/MediumVolume.h.
// Throws InputError (file, grid, reason) for a missing/unreadable file, a
// missing grid (the message lists the grids present) or a non-scalar grid.
// Recoverable oddities (empty grid, NaN/Inf, negative density) come back as
// VolumeGrids::warnings. A grid past `limits` throws InputError (file, grid,
// the limit, the "downsample" that would fit) before its dense array exists.
VolumeGrids load_volume(const VolumeOptions& options, const DenseLimits& limits = {});

// The most texels one dense grid may have (default 2^32, 16 GiB as float:
// past what any host or device here holds); beyond it load_volume throws
// InputError and suggests "downsample". The fuzz target and the corrupt-input
// tests lower it: a few bytes of active tiles can describe a legitimately huge
// volume, and allocating it teaches them nothing.
void set_max_dense_texels(uint64_t texels);

// The most leaves a grid kept sparse may have once its active tiles are
// voxelized (default 2^32 - 1, what NanoVDB's 32-bit node counts hold);
// beyond it load_volume throws InputError. The fuzz targets lower it, as
// set_max_dense_texels, to stay within libFuzzer's memory limit.
void set_max_sparse_leaves(uint64_t leaves);

}  // namespace pyrolume
