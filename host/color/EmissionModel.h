#pragma once
// What every emitter obeys in both renderers. The GPU's copies in
// shaders/shared/gpu_types.h are asserted equal in render/vulkan/GpuScene.cpp.
namespace pyrolume {

// The most radiance any emitter (a medium's emission, an environment texel
// times its scale) may give: beyond it the renderers' float sums could
// overflow (docs/robustness.md "Finite by construction"); refused at load.
inline constexpr float kMaxEmittedRadiance = 1e12f;

}  // namespace pyrolume
