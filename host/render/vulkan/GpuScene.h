#pragma once
// Scene -> the structs in shaders/shared/gpu_types.h.
#include <vector>

#include "render/Render.h"
#include "scene/Scene.h"
#include "shared/gpu_types.h"

namespace pyrolume {

std::vector<gpu::GpuMedium> build_gpu_media(const Scene& scene);
gpu::FrameConstants build_frame_constants(const Scene& scene, const RenderSettings& settings, uint32_t medium_count);

}  // namespace pyrolume
