#include "render/vulkan/Memory.h"

// Vulkan structs are written {.sType = ...}: the rest is zero by design.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>
#include <type_traits>
#include <utility>

namespace pyrolume::vk {

namespace {

std::string mib(VkDeviceSize bytes) {
  char s[32];
  std::snprintf(s, sizeof s, "%.1f MiB", double(bytes) / (1024.0 * 1024.0));
  return s;
}

std::string label(const char* name) { return name ? std::string("'") + name + "'" : std::string("a resource"); }

// Property flags to try for each kind, best first.
std::vector<VkMemoryPropertyFlags> preferences(MemoryKind kind) {
  constexpr auto local = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, visible = VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT,
                 coherent = VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, cached = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;
  switch (kind) {
    case MemoryKind::DeviceLocal: return {local, 0};
    case MemoryKind::HostVisible: return {visible | coherent, visible};
    // Cached: the host reads it back, and uncached reads are very slow.
    case MemoryKind::Readback: return {visible | cached | coherent, visible | cached, visible | coherent, visible};
  }
  return {0};
}

// A clear error before the driver's bare VK_ERROR_OUT_OF_DEVICE_MEMORY.
void check_fits(const Context& ctx, VkDeviceSize bytes, uint32_t type_bits, MemoryKind kind, const char* name) {
  const auto& props = ctx.memory_properties();
  VkDeviceSize largest = 0;
  for (VkMemoryPropertyFlags want : preferences(kind))
    for (uint32_t i = 0; i < props.memoryTypeCount; ++i)
      if ((type_bits & (1u << i)) && (props.memoryTypes[i].propertyFlags & want) == want)
        largest = std::max(largest, props.memoryHeaps[props.memoryTypes[i].heapIndex].size);
  if (bytes > largest)
    throw VulkanError("cannot allocate " + label(name) + " of " + mib(bytes) + ": the largest suitable memory heap of " +
                          ctx.info().name + " has " + mib(largest),
                      VK_ERROR_OUT_OF_DEVICE_MEMORY);
  if (ctx.max_allocation_size() && bytes > ctx.max_allocation_size())
    throw VulkanError("cannot allocate " + label(name) + " of " + mib(bytes) + ": " + ctx.info().name +
                          " allows at most " + mib(ctx.max_allocation_size()) + " per allocation",
                      VK_ERROR_OUT_OF_DEVICE_MEMORY);
}

struct Allocation {
  UniqueDeviceMemory memory;
  VkMemoryPropertyFlags flags = 0;
};

Allocation allocate(Context& ctx, const VkMemoryRequirements& req, MemoryKind kind, const char* name) {
  check_fits(ctx, req.size, req.memoryTypeBits, kind, name);
  int type = find_memory_type(ctx.memory_properties(), req.memoryTypeBits, kind);
  if (type < 0) throw VulkanError("no suitable memory type for " + label(name) + " on " + ctx.info().name);
  VkMemoryAllocateInfo ai{.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  ai.allocationSize = req.size;
  ai.memoryTypeIndex = uint32_t(type);
  VkDeviceMemory mem = VK_NULL_HANDLE;
  VkResult r = vkAllocateMemory(ctx.device(), &ai, nullptr, &mem);
  if (r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY)
    throw VulkanError("out of memory allocating " + label(name) + " of " + mib(req.size) + " on " +
                          ctx.info().name + " (" + vk_result_name(r) + ")",
                      r);
  VK_CHECK(r);
  Allocation a{UniqueDeviceMemory(mem, {ctx.device()}), ctx.memory_properties().memoryTypes[type].propertyFlags};
  ctx.set_name(mem, name);
  return a;
}

// Memory for a new buffer or image, bound to it at offset 0.
template <class Handle>
Allocation bind_memory(Context& ctx, Handle handle, MemoryKind kind, const char* name) {
  constexpr bool buffer = std::is_same_v<Handle, VkBuffer>;
  VkMemoryRequirements req;
  if constexpr (buffer) vkGetBufferMemoryRequirements(ctx.device(), handle, &req);
  else vkGetImageMemoryRequirements(ctx.device(), handle, &req);
  Allocation a = allocate(ctx, req, kind, name);
  VkResult r;
  if constexpr (buffer) r = vkBindBufferMemory(ctx.device(), handle, a.memory.get(), 0);
  else r = vkBindImageMemory(ctx.device(), handle, a.memory.get(), 0);
  VK_CHECK(r);
  return a;
}

}  // namespace

int find_memory_type(const VkPhysicalDeviceMemoryProperties& props, uint32_t type_bits, MemoryKind kind) {
  for (VkMemoryPropertyFlags want : preferences(kind))
    for (uint32_t i = 0; i < props.memoryTypeCount; ++i)
      if ((type_bits & (1u << i)) && (props.memoryTypes[i].propertyFlags & want) == want) return int(i);
  return -1;
}

void memory_barrier(VkCommandBuffer cmd, VkPipelineStageFlags src_stage, VkAccessFlags src_access,
                    VkPipelineStageFlags dst_stage, VkAccessFlags dst_access) {
  VkMemoryBarrier b{.sType = VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  b.srcAccessMask = src_access;
  b.dstAccessMask = dst_access;
  vkCmdPipelineBarrier(cmd, src_stage, dst_stage, 0, 1, &b, 0, nullptr, 0, nullptr);
}

void to_host_read_barrier(VkCommandBuffer cmd) {
  memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                 VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                 VK_ACCESS_HOST_READ_BIT);
}

// --- Buffer ---

Buffer::Buffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, MemoryKind kind, const char* name)
    : device_(ctx.device()), size_(size), kind_(kind), atom_(ctx.properties().limits.nonCoherentAtomSize) {
  if (size == 0) throw VulkanError("cannot create " + label(name) + ": buffer size 0");
  check_fits(ctx, size, ~0u, kind, name);  // before vkCreateBuffer, which may reject huge sizes itself
  VkBufferCreateInfo bci{.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  bci.size = size;
  bci.usage = usage;
  bci.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer buf = VK_NULL_HANDLE;
  VK_CHECK(vkCreateBuffer(device_, &bci, nullptr, &buf));
  buffer_ = UniqueBuffer(buf, {device_});
  ctx.set_name(buf, name);
  Allocation a = bind_memory(ctx, buf, kind, name);
  memory_ = std::move(a.memory);
  if (a.flags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) {
    VK_CHECK(vkMapMemory(device_, memory_.get(), 0, VK_WHOLE_SIZE, 0, &mapped_));
    coherent_ = (a.flags & VK_MEMORY_PROPERTY_HOST_COHERENT_BIT) != 0;
  }
}

Buffer::Buffer(Buffer&& o) noexcept
    : device_(o.device_),
      memory_(std::move(o.memory_)),
      buffer_(std::move(o.buffer_)),
      size_(std::exchange(o.size_, 0)),
      kind_(o.kind_),
      mapped_(std::exchange(o.mapped_, nullptr)),
      coherent_(o.coherent_),
      atom_(o.atom_) {}

Buffer& Buffer::operator=(Buffer&& o) noexcept {
  if (this != &o) {
    buffer_.reset();  // the buffer goes before its memory
    device_ = o.device_;
    memory_ = std::move(o.memory_);
    buffer_ = std::move(o.buffer_);
    size_ = std::exchange(o.size_, 0);
    kind_ = o.kind_;
    mapped_ = std::exchange(o.mapped_, nullptr);
    coherent_ = o.coherent_;
    atom_ = o.atom_;
  }
  return *this;
}

void* Buffer::map() const {
  if (!mapped_) throw VulkanError("Buffer::map: buffer is not host-visible (MemoryKind::DeviceLocal)");
  return mapped_;
}

namespace {
// Non-coherent ranges must be multiples of nonCoherentAtomSize.
VkMappedMemoryRange aligned_range(VkDeviceMemory mem, VkDeviceSize offset, VkDeviceSize size, VkDeviceSize total,
                                  VkDeviceSize atom) {
  VkMappedMemoryRange r{.sType = VK_STRUCTURE_TYPE_MAPPED_MEMORY_RANGE};
  r.memory = mem;
  r.offset = offset / atom * atom;
  if (size == VK_WHOLE_SIZE || offset + size >= total)
    r.size = VK_WHOLE_SIZE;
  else
    r.size = (offset + size - r.offset + atom - 1) / atom * atom;
  return r;
}
}  // namespace

void Buffer::flush(VkDeviceSize offset, VkDeviceSize size) const {
  if (coherent_ || !mapped_) return;
  VkMappedMemoryRange r = aligned_range(memory_.get(), offset, size, size_, atom_);
  VK_CHECK(vkFlushMappedMemoryRanges(device_, 1, &r));
}

void Buffer::invalidate(VkDeviceSize offset, VkDeviceSize size) const {
  if (coherent_ || !mapped_) return;
  VkMappedMemoryRange r = aligned_range(memory_.get(), offset, size, size_, atom_);
  VK_CHECK(vkInvalidateMappedMemoryRanges(device_, 1, &r));
}

void Buffer::upload(Context& ctx, const void* src, VkDeviceSize bytes, VkDeviceSize offset) {
  if (offset + bytes > size_)
    throw VulkanError("Buffer::upload: " + std::to_string(bytes) + " bytes at offset " + std::to_string(offset) +
                      " overrun a buffer of " + std::to_string(size_));
  if (bytes == 0) return;
  if (mapped_) {
    std::memcpy(static_cast<char*>(mapped_) + offset, src, bytes);
    flush(offset, bytes);
    return;
  }
  // In pieces of at most kStagingBytes: a large buffer (a sparse grid's
  // tree) never needs a second copy of itself in host memory (on lavapipe the
  // device's memory is host memory too).
  constexpr VkDeviceSize kStagingBytes = VkDeviceSize(64) << 20;
  Buffer staging(ctx, std::min(bytes, kStagingBytes), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryKind::HostVisible,
                 "staging upload");
  for (VkDeviceSize done = 0; done < bytes; done += kStagingBytes) {
    const VkDeviceSize piece = std::min(bytes - done, kStagingBytes);
    std::memcpy(staging.map(), static_cast<const char*>(src) + done, piece);
    staging.flush();
    ctx.submit_and_wait([&](VkCommandBuffer cmd) {
      // Earlier work on this buffer finishes before the copy overwrites it.
      memory_barrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_TRANSFER_WRITE_BIT);
      VkBufferCopy copy{0, offset + done, piece};
      vkCmdCopyBuffer(cmd, staging.buffer(), buffer(), 1, &copy);
      memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_READ_BIT | VK_ACCESS_MEMORY_WRITE_BIT);
    });
  }
}

const void* Buffer::read_in_place(Context& ctx, VkDeviceSize bytes, VkDeviceSize offset) {
  if (offset + bytes > size_)
    throw VulkanError("Buffer::read_in_place: " + std::to_string(bytes) + " bytes at offset " +
                      std::to_string(offset) + " overrun a buffer of " + std::to_string(size_));
  if (!mapped_) return nullptr;
  // An empty submission orders all earlier work before the host read.
  ctx.submit_and_wait([](VkCommandBuffer cmd) {
    memory_barrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                   VK_ACCESS_HOST_READ_BIT);
  });
  if (bytes > 0) invalidate(offset, bytes);
  return static_cast<const char*>(mapped_) + offset;
}

void Buffer::download(Context& ctx, void* dst, VkDeviceSize bytes, VkDeviceSize offset) {
  if (offset + bytes > size_)
    throw VulkanError("Buffer::download: " + std::to_string(bytes) + " bytes at offset " + std::to_string(offset) +
                      " overrun a buffer of " + std::to_string(size_));
  if (bytes == 0) return;
  if (const void* src = read_in_place(ctx, bytes, offset)) {
    std::memcpy(dst, src, bytes);
    return;
  }
  Buffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, MemoryKind::Readback, "staging readback");
  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    memory_barrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_ACCESS_MEMORY_WRITE_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                   VK_ACCESS_TRANSFER_READ_BIT);
    VkBufferCopy copy{offset, 0, bytes};
    vkCmdCopyBuffer(cmd, buffer(), staging.buffer(), 1, &copy);
    memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_HOST_BIT,
                   VK_ACCESS_HOST_READ_BIT);
  });
  staging.invalidate();
  std::memcpy(dst, staging.map(), bytes);
}

// --- images ---

uint32_t texel_bytes(VkFormat format) {
  switch (format) {
    case VK_FORMAT_R8_UNORM: return 1;
    case VK_FORMAT_R16_SFLOAT:
    case VK_FORMAT_R16_UNORM: return 2;
    case VK_FORMAT_R32_SFLOAT:
    case VK_FORMAT_R16G16_SFLOAT:
    case VK_FORMAT_R8G8B8A8_UNORM:
    case VK_FORMAT_R8G8B8A8_SRGB: return 4;
    case VK_FORMAT_R32G32_SFLOAT:
    case VK_FORMAT_R16G16B16A16_SFLOAT: return 8;
    case VK_FORMAT_R32G32B32A32_SFLOAT: return 16;
    default: throw VulkanError("texel_bytes: unsupported image format " + std::to_string(int(format)));
  }
}

SampledImage::SampledImage(Context& ctx, VkImageType type, VkExtent3D extent, VkFormat format,
                           const VkSamplerCreateInfo& sampler, const char* name)
    : format_(format), extent_(extent) {
  const VkDevice dev = ctx.device();
  const auto& limits = ctx.properties().limits;
  uint32_t max_dim = type == VK_IMAGE_TYPE_1D ? limits.maxImageDimension1D
                     : type == VK_IMAGE_TYPE_2D ? limits.maxImageDimension2D
                                                : limits.maxImageDimension3D;
  if (extent.width == 0 || extent.height == 0 || extent.depth == 0 || extent.width > max_dim ||
      extent.height > max_dim || extent.depth > max_dim)
    throw VulkanError("cannot create image " + label(name) + " of " + std::to_string(extent.width) + "x" +
                      std::to_string(extent.height) + "x" + std::to_string(extent.depth) + ": each side must be 1.." +
                      std::to_string(max_dim) + " on " + ctx.info().name);
  // Linear filtering of R32F is optional in Vulkan (R16F is mandatory).
  VkFormatProperties fp;
  vkGetPhysicalDeviceFormatProperties(ctx.physical_device(), format, &fp);
  const VkFormatFeatureFlags need = VK_FORMAT_FEATURE_SAMPLED_IMAGE_BIT | VK_FORMAT_FEATURE_TRANSFER_DST_BIT |
                                    (sampler.magFilter == VK_FILTER_LINEAR ? VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT : 0);
  if ((fp.optimalTilingFeatures & need) != need)
    throw VulkanError("cannot create image " + label(name) + ": format " + std::to_string(int(format)) +
                          " cannot be sampled with linear filtering on " + ctx.info().name,
                      VK_ERROR_FORMAT_NOT_SUPPORTED);
  check_fits(ctx, VkDeviceSize(extent.width) * extent.height * extent.depth * texel_bytes(format), ~0u,
             MemoryKind::DeviceLocal, name);

  VkImageCreateInfo ici{.sType = VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  ici.imageType = type;
  ici.format = format;
  ici.extent = extent;
  ici.mipLevels = 1;
  ici.arrayLayers = 1;
  ici.samples = VK_SAMPLE_COUNT_1_BIT;
  ici.tiling = VK_IMAGE_TILING_OPTIMAL;
  ici.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  ici.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  ici.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImage img = VK_NULL_HANDLE;
  VK_CHECK(vkCreateImage(dev, &ici, nullptr, &img));
  image_ = UniqueImage(img, {dev});
  ctx.set_name(img, name);
  memory_ = bind_memory(ctx, img, MemoryKind::DeviceLocal, name).memory;

  VkImageViewCreateInfo vci{.sType = VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  vci.image = img;
  vci.viewType = type == VK_IMAGE_TYPE_1D ? VK_IMAGE_VIEW_TYPE_1D
                 : type == VK_IMAGE_TYPE_2D ? VK_IMAGE_VIEW_TYPE_2D
                                            : VK_IMAGE_VIEW_TYPE_3D;
  vci.format = format;
  vci.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  VkImageView view = VK_NULL_HANDLE;
  VK_CHECK(vkCreateImageView(dev, &vci, nullptr, &view));
  view_ = UniqueImageView(view, {dev});
  ctx.set_name(view, name);

  VkSampler smp = VK_NULL_HANDLE;
  VK_CHECK(vkCreateSampler(dev, &sampler, nullptr, &smp));
  sampler_ = UniqueSampler(smp, {dev});
  ctx.set_name(smp, name);
}

void SampledImage::upload(Context& ctx, const void* src, size_t bytes) {
  const size_t expected = size_t(extent_.width) * extent_.height * extent_.depth * texel_bytes(format_);
  if (bytes != expected)
    throw VulkanError("SampledImage::upload: got " + std::to_string(bytes) + " bytes, the image holds " +
                      std::to_string(expected));
  Buffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, MemoryKind::HostVisible, "staging image upload");
  std::memcpy(staging.map(), src, bytes);
  staging.flush();
  ctx.submit_and_wait([&](VkCommandBuffer cmd) {
    VkImageMemoryBarrier b{.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image_.get();
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
    // UNDEFINED: old contents are discarded; the execution dependency covers
    // shaders still reading a previous upload.
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.srcAccessMask = 0;
    b.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
    copy.imageExtent = extent_;
    vkCmdCopyBufferToImage(cmd, staging.buffer(), image_.get(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
    b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
    b.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
    b.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    b.dstAccessMask = VK_ACCESS_SHADER_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 0, nullptr, 0,
                         nullptr, 1, &b);
  });
}

namespace {
VkSamplerCreateInfo linear_sampler(VkSamplerAddressMode mode) {
  VkSamplerCreateInfo s{.sType = VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
  s.magFilter = s.minFilter = VK_FILTER_LINEAR;
  s.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
  s.addressModeU = s.addressModeV = s.addressModeW = mode;
  s.borderColor = VK_BORDER_COLOR_FLOAT_TRANSPARENT_BLACK;
  s.maxLod = 0.0f;
  return s;
}
}  // namespace

UniqueBufferView texel_buffer_view(Context& ctx, const Buffer& buffer, VkFormat format) {
  const VkBufferViewCreateInfo vi{.sType = VK_STRUCTURE_TYPE_BUFFER_VIEW_CREATE_INFO,
                                  .pNext = nullptr,
                                  .flags = 0,
                                  .buffer = buffer.buffer(),
                                  .format = format,
                                  .offset = 0,
                                  .range = VK_WHOLE_SIZE};
  VkBufferView view = VK_NULL_HANDLE;
  VK_CHECK(vkCreateBufferView(ctx.device(), &vi, nullptr, &view));
  return UniqueBufferView(view, {ctx.device()});
}

Image3D::Image3D(Context& ctx, uint32_t width, uint32_t height, uint32_t depth, VkFormat format, const char* name)
    : SampledImage(ctx, VK_IMAGE_TYPE_3D, {width, height, depth}, format,
                   linear_sampler(VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_BORDER), name) {}

namespace {
VkSamplerCreateInfo sampler_2d(VkSamplerAddressMode u_mode, VkSamplerAddressMode v_mode) {
  VkSamplerCreateInfo s = linear_sampler(u_mode);
  s.addressModeV = v_mode;
  s.addressModeW = v_mode;
  return s;
}
}  // namespace

Image2D::Image2D(Context& ctx, uint32_t width, uint32_t height, VkFormat format, VkSamplerAddressMode u_mode,
                 VkSamplerAddressMode v_mode, const char* name)
    : SampledImage(ctx, VK_IMAGE_TYPE_2D, {width, height, 1}, format, sampler_2d(u_mode, v_mode), name) {}

Image1D::Image1D(Context& ctx, uint32_t width, VkFormat format, const char* name)
    : SampledImage(ctx, VK_IMAGE_TYPE_1D, {width, 1, 1}, format,
                   linear_sampler(VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE), name) {}

}  // namespace pyrolume::vk
