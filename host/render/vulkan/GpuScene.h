#pragma once
// Scene (+ its loaded grids) -> the structs in shaders/shared/gpu_types.h.
#include <optional>
#include <vector>

#include "color/BlackbodyLut.h"
#include "render/Render.h"
#include "scene/Scene.h"
#include "shared/gpu_types.h"
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
  std::vector<float> majorants;             // every grid's cells, at GpuGrid::majorant_res.w
  bool has_grids = false, has_scattering = false, has_emission = false;
  bool has_analytic = false;  // a sphere or box medium
};

// volumes[i] holds medium i's grids when it is a vdb medium. Empty grids are
// left out (they render as no medium). `with_luts` = false skips the blackbody
// LUT bake (for updates that keep the existing textures).
GpuScene build_gpu_scene(const Scene& scene, const std::vector<std::optional<StoredVolume>>& volumes,
                         bool with_luts = true);
gpu::FrameConstants build_frame_constants(const Scene& scene, const RenderSettings& settings, uint32_t medium_count);

}  // namespace pyrolume
