#pragma once
// A compute pipeline with one descriptor set and an optional push-constant
// block, and a descriptor set allocated from its own pool.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <list>
#include <memory>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "render/vulkan/Context.h"
#include "render/vulkan/Handles.h"
#include "render/vulkan/Memory.h"

namespace pyrolume::vk {

class ComputePipeline {
 public:
  struct Binding {
    uint32_t binding;
    VkDescriptorType type;
    uint32_t count = 1;  // > 1: an array of descriptors (e.g. sampler3D tex[4])
  };
  // specialization: (constant_id, 32-bit value as a bit pattern). Every
  // constant is 4 bytes: use std::bit_cast for floats, 0/1 for bools.
  ComputePipeline(Context& ctx, const std::vector<uint32_t>& spirv, const std::vector<Binding>& bindings,
                  uint32_t push_constant_bytes,
                  const std::vector<std::pair<uint32_t, uint32_t>>& specialization, const char* debug_name);

  VkPipeline pipeline() const { return pipeline_.get(); }
  VkPipelineLayout layout() const { return layout_.get(); }
  VkDescriptorSetLayout set_layout() const { return set_layout_.get(); }
  const std::vector<Binding>& bindings() const { return bindings_; }
  uint32_t push_constant_bytes() const { return push_constant_bytes_; }
  const std::string& name() const { return name_; }

  // Binds the pipeline and `set` (set = 0) for dispatch.
  void bind(VkCommandBuffer cmd, VkDescriptorSet set) const;
  // bytes must not exceed push_constant_bytes. Only for small shaders or
  // values that never change: a value that changes per dispatch belongs in a
  // ParameterBuffer (below).
  void push(VkCommandBuffer cmd, const void* data, uint32_t bytes) const;
  template <typename T>
  void push(VkCommandBuffer cmd, const T& value) const {
    push(cmd, &value, uint32_t(sizeof(T)));
  }

 private:
  std::vector<Binding> bindings_;
  uint32_t push_constant_bytes_ = 0;
  std::string name_;
  UniqueDescriptorSetLayout set_layout_;
  UniquePipelineLayout layout_;
  UniquePipeline pipeline_;
};

// The pipelines a device already made, for the sessions that ask again for
// the same shader, bindings and specialisation: a test or a tool that opens
// one session per render, a preview that reloads its scene. On lavapipe a
// megakernel pipeline costs ~0.5 CPU-s (SPIR-V specialisation, then NIR);
// 83 of the 330 pipelines the Vulkan and hard-case tests made repeated one
// their process had made before (docs/testing.md "Build and CI time").
// The most recently used kCapacity stay; a session keeps its own alive.
class PipelineCache {
 public:
  static constexpr size_t kCapacity = 8;

  explicit PipelineCache(Context& ctx) : ctx_(ctx) {}

  // The pipeline ComputePipeline(ctx, spirv, bindings, ...) would make,
  // made once per distinct set of arguments (the debug name included).
  std::shared_ptr<const ComputePipeline> get(const std::vector<uint32_t>& spirv,
                                             const std::vector<ComputePipeline::Binding>& bindings,
                                             uint32_t push_constant_bytes,
                                             const std::vector<std::pair<uint32_t, uint32_t>>& specialization,
                                             const char* debug_name);

 private:
  Context& ctx_;
  struct Entry {
    std::vector<uint32_t> key;  // every argument, the SPIR-V words whole
    std::shared_ptr<const ComputePipeline> pipeline;
  };
  std::mutex mutex_;
  std::list<Entry> entries_;  // most recently used first
};

// Values that change from one dispatch to the next (a pass's samples and
// rows, a filter's step), read by the shader from a storage buffer rather
// than from push constants or a uniform buffer. lavapipe (Mesa 22.x) inlines
// the push-constant and uniform values that decide a branch or a loop count
// and JIT-compiles a new variant of the shader for each dispatch that binds
// them; the variants are never freed, so every pass cost a compile and about
// 0.5 MB (docs/robustness.md "Constant memory over a long sequence"). Values
// in a storage buffer are never inlined: the shader is compiled once, with
// its pipeline.
class ParameterBuffer {
 public:
  ParameterBuffer() = default;
  ParameterBuffer(Context& ctx, VkDeviceSize bytes, const char* name);

  const Buffer& buffer() const { return buffer_; }

  // Records the write of `bytes` of `data` (a multiple of 4, at most the
  // buffer's size) into the command buffer, after the shader reads of earlier
  // dispatches and before those of later ones.
  void record(VkCommandBuffer cmd, const void* data, VkDeviceSize bytes) const;
  template <typename T>
  void record(VkCommandBuffer cmd, const T& value) const {
    record(cmd, &value, sizeof(T));
  }

 private:
  Buffer buffer_;
};

// One descriptor set for a pipeline's set layout, from a pool of its own (freed
// with it). Every binding must be written before the first dispatch.
class DescriptorSet {
 public:
  DescriptorSet(Context& ctx, const ComputePipeline& pipeline, const char* debug_name = nullptr);

  VkDescriptorSet set() const { return set_; }

  void write_buffer(uint32_t binding, const Buffer& buffer, VkDeviceSize offset = 0,
                    VkDeviceSize range = VK_WHOLE_SIZE);
  // A storage texel buffer's view.
  void write_texel_buffer(uint32_t binding, VkBufferView view, uint32_t array_element = 0);
  void write_image(uint32_t binding, VkImageView view, VkSampler sampler,
                   VkImageLayout layout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, uint32_t array_element = 0);
  void write_image(uint32_t binding, const SampledImage& image, uint32_t array_element = 0) {
    write_image(binding, image.view(), image.sampler(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, array_element);
  }

 private:
  VkDescriptorType type_of(uint32_t binding) const;
  void write(uint32_t binding, uint32_t array_element, const VkDescriptorBufferInfo* buffer,
             const VkDescriptorImageInfo* image, const VkBufferView* texel_buffer);

  VkDevice device_ = VK_NULL_HANDLE;
  std::vector<ComputePipeline::Binding> bindings_;
  UniqueDescriptorPool pool_;
  VkDescriptorSet set_ = VK_NULL_HANDLE;  // freed with the pool
};

}  // namespace pyrolume::vk
