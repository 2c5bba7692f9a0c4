// The common subset of GLSL and C++ that every header in shaders/shared/ is
// written in: on the C++ side GLM's vec2/vec3/vec4/ivec3/uvec3/uvec4 and `uint` inside
// pyrolume::gpu, and PYRO_CONST for constants both languages accept.
#ifndef PYROLUME_SHARED_COMMON_H
#define PYROLUME_SHARED_COMMON_H

#ifdef __cplusplus
#include <cstddef>
#include <cstdint>
#include <glm/glm.hpp>
namespace pyrolume::gpu {
using vec2 = glm::vec2;
using vec3 = glm::vec3;
using vec4 = glm::vec4;
using ivec3 = glm::ivec3;
using uvec3 = glm::uvec3;
using uvec4 = glm::uvec4;
using uint = uint32_t;
}  // namespace pyrolume::gpu
#define PYRO_CONST constexpr
// A shared struct's field sits where std140/std430 put it.
#define PYRO_OFFSET(S, field, at) static_assert(offsetof(S, field) == (at))
#else
#define PYRO_CONST const
#endif

#endif
