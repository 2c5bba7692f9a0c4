#pragma once
// Buffers and sampled images with their own memory (one allocation each: the
// renderer has a handful of large resources, so no sub-allocator).
#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>

#include "render/vulkan/Context.h"
#include "render/vulkan/Handles.h"

namespace pyrolume::vk {

enum class MemoryKind {
  DeviceLocal,  // GPU only; filled by copies or shaders
  HostVisible,  // host writes, device reads (uniforms, staging); persistently mapped
  Readback,     // device writes, host reads (cached where possible); persistently mapped
};

// Index of the memory type for `kind` among `type_bits`, or -1.
int find_memory_type(const VkPhysicalDeviceMemoryProperties& props, uint32_t type_bits, MemoryKind kind);

// Global memory barrier (all buffers and images).
void memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src_access,
                    VkPipelineStageFlags dst_stage, VkAccessFlags dst_access);
// Compute shader or transfer writes -> host reads (before reading a Readback buffer).
void to_host_read_barrier(VkCommandBuffer cmd);

class Buffer {
 public:
  Buffer() = default;
  Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryKind kind, const char* name = nullptr);
  Buffer(Buffer&& o) noexcept;
  Buffer& operator=(Buffer&& o) noexcept;

  VkBuffer buffer() const { return buffer_.get(); }
  VkDeviceSize size() const { return size_; }
  MemoryKind kind() const { return kind_; }
  explicit operator bool() const { return bool(buffer_); }
  VkDescriptorBufferInfo descriptor() const { return {buffer_.get(), 0, VK_WHOLE_SIZE}; }

  // Persistent mapping of a host-visible buffer; throws for DeviceLocal memory
  // that is not host-visible.
  void* map() const;
  template <typename T>
  T* data() const { return static_cast<T*>(map()); }
  bool host_coherent() const { return coherent_; }
  bool host_visible() const { return mapped_ != nullptr; }
  // Make host writes visible to the device / device writes visible to the host
  // (no-ops on coherent memory). The device-side barrier is still the caller's.
  void flush(VkDeviceSize offset = 0, VkDeviceSize size = VK_WHOLE_SIZE) const;
  void invalidate(VkDeviceSize offset = 0, VkDeviceSize size = VK_WHOLE_SIZE) const;

  // Host -> buffer. Mapped: memcpy + flush. Otherwise through a staging buffer
  // (needs TRANSFER_DST usage), followed by a barrier to all later commands.
  void upload(Context& ctx, const void* src, VkDeviceSize bytes, VkDeviceSize offset = 0);
  // Buffer -> host, waiting for all earlier submitted work. Unmapped buffers go
  // through a staging buffer (needs TRANSFER_SRC usage).
  void download(Context& ctx, void* dst, VkDeviceSize bytes, VkDeviceSize offset = 0);
  // A host-visible buffer's bytes [offset, offset + bytes) where the host can
  // read them in place, after all earlier submitted work; nullptr for a buffer
  // that is not host-visible (then download). Saves a copy where device
  // memory is host memory (lavapipe, integrated GPUs).
  const void* read_in_place(Context& ctx, VkDeviceSize bytes, VkDeviceSize offset = 0);

 private:
  VkDevice device_ = VK_NULL_HANDLE;
  UniqueDeviceMemory memory_;  // before buffer_: the buffer is destroyed first
  UniqueBuffer buffer_;
  VkDeviceSize size_ = 0;
  MemoryKind kind_ = MemoryKind::DeviceLocal;
  void* mapped_ = nullptr;
  bool coherent_ = true;
  VkDeviceSize atom_ = 1;  // nonCoherentAtomSize
};

// A view of the whole buffer as texels of `format` (a texel-buffer binding).
UniqueBufferView texel_buffer_view(Context& ctx, const Buffer& buffer, VkFormat format);

// A sampled image with its view and sampler, filled from host data. Texels are
// tightly packed, x fastest, then y, then z. After upload() it stays in
// SHADER_READ_ONLY_OPTIMAL.
class SampledImage {
 public:
  SampledImage() = default;
  SampledImage(SampledImage&&) noexcept = default;
  SampledImage& operator=(SampledImage&&) noexcept = default;

  VkImage image() const { return image_.get(); }
  VkImageView view() const { return view_.get(); }
  VkSampler sampler() const { return sampler_.get(); }
  VkFormat format() const { return format_; }
  VkExtent3D extent() const { return extent_; }
  explicit operator bool() const { return bool(image_); }
  VkDescriptorImageInfo descriptor() const {
    return {sampler_.get(), view_.get(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
  }
  // bytes must equal width*height*depth*texel size.
  void upload(Context& ctx, const void* src, size_t bytes);

 protected:
  SampledImage(Context& ctx, VkImageType type, VkExtent3D extent, VkFormat format,
               const VkSamplerCreateInfo& sampler, const char* name);

 private:
  UniqueDeviceMemory memory_;
  UniqueImage image_;
  UniqueImageView view_;
  UniqueSampler sampler_;
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  VkExtent3D extent_{0, 0, 0};
};

// Bytes per texel of the formats pyrolume uploads; throws for others.
uint32_t texel_bytes(VkFormat format);

// A 3D grid (density, temperature): trilinear filtering, clamp-to-border with
// a transparent black border, so lookups outside the grid read 0.
class Image3D : public SampledImage {
 public:
  Image3D() = default;
  Image3D(Context& ctx, uint32_t width, uint32_t height, uint32_t depth, VkFormat format, const char* name = nullptr);
};

// A 2D texture (albedo textures, environment maps): linear filtering; `u_mode`
// and `v_mode` are the address modes (REPEAT for tiling textures and the
// lat-long map's longitude, CLAMP_TO_EDGE for its latitude).
class Image2D : public SampledImage {
 public:
  Image2D() = default;
  Image2D(Context& ctx, uint32_t width, uint32_t height, VkFormat format, VkSamplerAddressMode u_mode,
          VkSamplerAddressMode v_mode, const char* name = nullptr);
};

// A 1D table (blackbody LUT): linear filtering, clamp-to-edge.
class Image1D : public SampledImage {
 public:
  Image1D() = default;
  Image1D(Context& ctx, uint32_t width, VkFormat format, const char* name = nullptr);
};

}  // namespace pyrolume::vk
