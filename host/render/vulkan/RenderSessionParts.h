#pragma once
// Helpers that RenderSession's files share (RenderSession.cpp: set-up;
// RenderSessionFrame.cpp: loading a frame's grids, surfaces and lights;
// RenderSessionDispatch.cpp: passes; RenderSessionReadback.cpp: sums and
// checkpoint state). Not for other units.
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "render/SceneChecks.h"
#include "render/vulkan/Context.h"
#include "render/vulkan/Memory.h"
#include "scene/Scene.h"
#include "volume/StoredVolume.h"

namespace pyrolume::session {
inline constexpr VkBufferUsageFlags kUniform = VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
inline constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;

// A device-local storage buffer holding `values`; an empty vector gets one
// zeroed element (Vulkan has no empty buffers; the shader never reads it).
template <typename T>
inline vk::Buffer storage_buffer(vk::Context& ctx, const std::vector<T>& values, const char* name) {
  const std::vector<T> one(1);
  const std::vector<T>& v = values.empty() ? one : values;
  vk::Buffer b(ctx, v.size() * sizeof(T), kStorage, vk::MemoryKind::DeviceLocal, name);
  b.upload(ctx, v.data(), v.size() * sizeof(T));
  return b;
}

// A device-local uniform texel buffer holding `count` texels of `format` from
// `data`, and its view (majorant cells, density texels).
inline void uniform_texel_buffer(vk::Context& ctx, const void* data, size_t count, VkFormat format, size_t texel_bytes,
                          const char* name, vk::Buffer& buffer, vk::UniqueBufferView& view) {
  view = {};  // before its buffer goes
  buffer = vk::Buffer(ctx, count * texel_bytes, VK_BUFFER_USAGE_UNIFORM_TEXEL_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                      vk::MemoryKind::DeviceLocal, name);
  buffer.upload(ctx, data, count * texel_bytes);
  view = vk::texel_buffer_view(ctx, buffer, format);
}

// What every grid medium must satisfy once loaded (render/SceneChecks.h).
inline void check_loaded_media(const Scene& scene, const std::vector<std::optional<StoredVolume>>& volumes) {
  for (size_t i = 0; i < volumes.size(); ++i)
    if (volumes[i]) check_loaded_medium(scene, i, *volumes[i]);
}

// Printed as a number, not through int: a forged size past 2^31 MiB would wrap.
inline std::string mib(double bytes) {
  char text[64];
  std::snprintf(text, sizeof text, "%.0f MiB", bytes / (1024.0 * 1024.0));
  return text;
}
}  // namespace pyrolume::session
