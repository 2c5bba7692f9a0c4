#pragma once
// Scene (+ its loaded grids) -> the structs in shaders/shared/gpu_types.h.
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "color/BlackbodyLut.h"
#include "light/LightSelection.h"
#include "render/LineEstimator.h"
#include "render/Render.h"
#include "scene/Scene.h"
#include "shared/gpu_types.h"
#include "volume/SparseGrid.h"
#include "volume/StoredVolume.h"

namespace pyrolume {

struct GpuGridSource {
  const StoredGrid* density = nullptr;
  const StoredGrid* temperature = nullptr;  // null unless the medium emits from its temperature
  std::optional<color::BlackbodyLut> blackbody;
  size_t medium = 0;  // index into Scene::media
};

struct GpuScene {
  std::vector<gpu::GpuMedium> media;
  std::vector<gpu::GpuGrid> grids;
  std::vector<GpuGridSource> grid_sources;  // per slot, same order as grids
  std::vector<float> majorants;             // every grid's cells, at GpuGrid::majorant_offset (and line rates)
  // Which media the line estimator collects, and the grid media's rates.
  LineMedia line;
  bool has_grids = false, has_scattering = false, has_emission = false;
  bool has_analytic = false;  // a sphere or box medium
  // Every emitting grid's temperature goes into its density texture's second
  // channel (temperature_fits_density_texture), so one lookup reads both.
  bool temperature_in_density = false;
  // What the sparse buffer holds (shaders/sparse.glsl): the zero leaf at
  // SPARSE_ZERO_LEAF, then each sparse grid's NanoVDB tree, a leaf of 512
  // copies for each value of its active tiles, and its leaf table (these in
  // sparse_tables), at these byte offsets; the buffer's size.
  struct SparseBlock {
    uint32_t offset = 0;
    const SparseGrid* tree = nullptr;  // or
    int table = -1;                    // an index into sparse_tables
  };
  std::vector<SparseBlock> sparse_blocks;
  std::vector<std::vector<uint32_t>> sparse_tables;
  uint64_t sparse_bytes = 0;
  bool has_sparse() const { return sparse_bytes > 0; }
};

// Whether a grid's temperature can be the second channel of its density
// texture: both grids share one index space, so the temperature at a density
// texel is a texel of its own, and the two-channel texture over the density's
// box costs at most a quarter more memory than the two textures apart and fits
// in max_bytes. Emission is σa·ρ·Le, zero wherever the density texture is, so
// the temperature outside the density's box is never needed.
bool temperature_fits_density_texture(const StoredGrid& density, const StoredGrid& temperature, uint64_t max_bytes);
// Bytes of that two-channel texture: RG16F when both grids are R16F, else RG32F.
uint64_t density_temperature_bytes(const StoredGrid& density, const StoredGrid& temperature);

// The two-channel texels (density, temperature) over the density's box, as
// RG16F bits when both grids are R16F (the uint16_t pairs) or RG32F floats.
struct DensityTemperatureTexels {
  bool half = true;
  std::vector<uint16_t> half_bits;
  std::vector<float> values;
};
DensityTemperatureTexels density_temperature_texels(const StoredGrid& density, const StoredGrid& temperature);

// volumes[i] holds medium i's grids when it is a vdb medium. Empty grids are
// left out (they render as no medium). `with_luts` = false skips the blackbody
// LUT bake (for updates that keep the existing textures); max_texture_bytes
// bounds one texture (the device's largest allocation). The composition of
// pack_gpu_media, add_majorant_cells and the temperature_in_density choice.
GpuScene build_gpu_scene(const Scene& scene, const std::vector<std::optional<StoredVolume>>& volumes,
                         bool with_luts = true,
                         uint64_t max_texture_bytes = std::numeric_limits<uint64_t>::max());
// The media and grid headers alone (no majorant cells: GpuGrid majorant_res,
// majorant_offset and majorant_cell stay 0; temperature_in_density false):
// all that a live edit of a medium's parameters changes. `line`: per scene
// medium, collected by the line estimator (line_media; missing: false).
// `with_tables` = false lays out the sparse buffer (the same offsets in the
// GpuGrids) without building its leaf tables (sparse_blocks and sparse_tables
// stay empty): an edit keeps the buffer it has.
GpuScene pack_gpu_media(const Scene& scene, const std::vector<std::optional<StoredVolume>>& volumes,
                        bool with_luts = true, const std::vector<bool>& line = {}, bool with_tables = true);
// Each grid's majorant cells (from its density as stored and the scene's
// integrator.majorant settings) into g.majorants, and where they lie into its
// GpuGrid; for the grid media with line rates (g.line.rates), the rates after them.
void add_majorant_cells(const Scene& scene, GpuScene& g);
// The fields of a GpuGrid that describe what the session baked (the blackbody
// LUT's coordinates, the majorant cells' geometry and line rates), copied from `baked`.
void keep_baked_grid_fields(const gpu::GpuGrid& baked, gpu::GpuGrid& grid);
// The grid's blackbody LUT coordinate map (GpuGrid lut_scale, lut_offset, t_min_k).
void set_blackbody_lut(gpu::GpuGrid& grid, const color::BlackbodyLutParams& p);

// The camera, image and integrator settings, and next-event estimation's choices.
gpu::FrameConstants build_frame_constants(const Scene& scene, const RenderSettings& settings, uint32_t medium_count,
                                          const LightSelection& lights);

}  // namespace pyrolume
