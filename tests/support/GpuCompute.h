#pragma once
// Running one of the test compute shaders (shaders/test_*.comp) by hand, for
// the tests that compare a shader's answers item by item with the C++ code it
// mirrors (header-only; Vulkan tests only): fill buffers, dispatch the shader
// over N items in workgroups of 64 and read the results back.
#include <cstdint>
#include <cstring>
#include <vector>

#include <vulkan/vulkan.h>

#include "render/vulkan/Context.h"
#include "render/vulkan/Memory.h"
#include "render/vulkan/Pipeline.h"
#include "render/vulkan/Spirv.h"

namespace pyrolume::test {

// A context with the validation layers on.
inline vk::Context::Options validated() {
  vk::Context::Options o;
  o.validation = true;
  return o;
}

// A buffer holding a copy of `bytes` bytes from `data` (a DeviceLocal buffer
// needs VK_BUFFER_USAGE_TRANSFER_DST_BIT in `usage`: it is filled through a
// staging buffer).
inline vk::Buffer filled_buffer(vk::Context& ctx, const void* data, size_t bytes, const char* name,
                                vk::MemoryKind kind = vk::MemoryKind::HostVisible,
                                VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT) {
  vk::Buffer b(ctx, bytes, usage, kind, name);
  b.upload(ctx, data, bytes);
  return b;
}
template <class T>
vk::Buffer filled_buffer(vk::Context& ctx, const std::vector<T>& items, const char* name,
                         vk::MemoryKind kind = vk::MemoryKind::HostVisible,
                         VkBufferUsageFlags usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT) {
  return filled_buffer(ctx, items.data(), items.size() * sizeof(T), name, kind, usage);
}

// A host-readable storage buffer the shader reads and answers in, holding a
// copy of `items` (read it back with read_back).
template <class T>
vk::Buffer in_out_buffer(vk::Context& ctx, const std::vector<T>& items, const char* name) {
  const size_t bytes = items.size() * sizeof(T);
  vk::Buffer b(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, vk::MemoryKind::Readback, name);
  std::memcpy(b.map(), items.data(), bytes);
  b.flush();
  return b;
}

// The items a dispatch left in a Readback buffer, into `items` (its size says
// how many).
template <class T>
void read_back(const vk::Buffer& b, std::vector<T>& items) {
  b.invalidate();
  std::memcpy(items.data(), b.map(), items.size() * sizeof(T));
}

// One dispatch of `pipeline` with `set` over `count` items (the shaders' local
// size is 64), `push` as the push constants, then a barrier to host reads;
// waits until it has run.
template <class Push>
void dispatch_and_wait(vk::Context& ctx, const vk::ComputePipeline& pipeline, const vk::DescriptorSet& set,
                       uint32_t count, const Push& push) {
  vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
    pipeline.bind(cmd, set.set());
    pipeline.push(cmd, push);
    vkCmdDispatch(cmd, (count + 63) / 64, 1, 1);
    vk::to_host_read_barrier(cmd);
  });
}

// A buffer bound to a shader's binding: a storage buffer unless `type` says
// otherwise.
struct BoundBuffer {
  const vk::Buffer* buffer;
  VkDescriptorType type = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
};

// Runs the compute shader `shader` ("test_bvh.comp") over `count` items, with
// buffers[i] at binding i, the item count as its one push constant (a uint)
// and the given specialization constants; waits until it has run.
inline void run_compute(vk::Context& ctx, const char* shader, const std::vector<BoundBuffer>& buffers, uint32_t count,
                        const std::vector<std::pair<uint32_t, uint32_t>>& specialization, const char* name) {
  std::vector<vk::ComputePipeline::Binding> bindings;
  for (uint32_t b = 0; b < buffers.size(); ++b) bindings.push_back({b, buffers[b].type});
  vk::ComputePipeline pipeline(ctx, vk::load_spirv(shader), bindings, sizeof(uint32_t), specialization, name);
  vk::DescriptorSet set(ctx, pipeline, name);
  for (uint32_t b = 0; b < buffers.size(); ++b) set.write_buffer(b, *buffers[b].buffer);
  dispatch_and_wait(ctx, pipeline, set, count, count);
}

}  // namespace pyrolume::test
