#include "preview/DisplayPass.h"

// Vulkan structs are written {.sType = ...}: the rest is zero by design.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

#include <algorithm>
#include <cmath>

#include "image/DisplayTransform.h"
#include "render/vulkan/Spirv.h"
#include "shared/preview_types.h"

namespace pyrolume::preview {

DisplayPass::DisplayPass(vk::Context& ctx, const vk::Buffer& accum, VkDeviceSize accum_bytes, uint32_t image_w,
                         uint32_t image_h)
    : ctx_(ctx),
      image_w_(image_w),
      image_h_(image_h),
      pipeline_(ctx, vk::load_spirv("preview_display.comp"),
                {{gpu::PREVIEW_BINDING_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                 {gpu::PREVIEW_BINDING_DISPLAY, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}},
                sizeof(gpu::DisplayConstants), {}, "preview display"),
      set_(ctx, pipeline_, "preview display set") {
  set_.write_buffer(gpu::PREVIEW_BINDING_ACCUM, accum, 0, accum_bytes);
}

void DisplayPass::resize(VkExtent2D target, bool bgra) {
  bgra_ = bgra;
  if (target.width == target_.width && target.height == target_.height && display_) return;
  target_ = target;
  rect_ = fit_image(image_w_, image_h_, target.width, target.height);
  // Device-local: written and read by the GPU every frame; only a screenshot
  // reads it on the host (through a staging copy).
  display_ = vk::Buffer(ctx_, VkDeviceSize(target.width) * target.height * 4,
                        VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT,
                        vk::MemoryKind::DeviceLocal, "preview display pixels");
  set_.write_buffer(gpu::PREVIEW_BINDING_DISPLAY, display_);
}

void DisplayPass::record(VkCommandBuffer cmd, int spp, double exposure_stops, ViewTransform view, VkImage image) {
  gpu::DisplayConstants dc{};
  dc.image_and_target = gpu::uvec4(image_w_, image_h_, target_.width, target_.height);
  dc.rect = gpu::uvec4(rect_.x, rect_.y, rect_.width, rect_.height);
  const float border = 0.08f;  // dark grey bars, so the image's own black edges stay visible
  dc.border = gpu::vec3(border);
  dc.radiance_scale = spp > 0 ? float(std::exp2(exposure_stops) / spp) : 0.0f;
  dc.swap_red_blue = bgra_ ? 1u : 0u;
  dc.view = view_shader_id(view);
  pipeline_.bind(cmd, set_.set());
  pipeline_.push(cmd, dc);
  const uint32_t g = gpu::PREVIEW_WORKGROUP_SIZE;
  vkCmdDispatch(cmd, (target_.width + g - 1) / g, (target_.height + g - 1) / g, 1);

  // The display buffer feeds the copy into the swapchain image (and a later
  // screenshot readback); the swapchain image becomes a copy destination.
  VkBufferMemoryBarrier bb{.sType = VK_STRUCTURE_TYPE_BUFFER_MEMORY_BARRIER};
  bb.srcAccessMask = VK_ACCESS_SHADER_WRITE_BIT;
  bb.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  bb.srcQueueFamilyIndex = bb.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  bb.buffer = display_.buffer();
  bb.size = VK_WHOLE_SIZE;
  VkImageMemoryBarrier ib{.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  ib.srcAccessMask = 0;  // the acquire semaphore (waited at TRANSFER) orders the presentation engine's reads
  ib.dstAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  ib.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;  // every pixel is overwritten
  ib.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  ib.srcQueueFamilyIndex = ib.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  ib.image = image;
  ib.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 1, &bb, 1, &ib);

  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {target_.width, target_.height, 1};
  vkCmdCopyBufferToImage(cmd, display_.buffer(), image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);

  ib.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  ib.dstAccessMask = 0;  // presentation is ordered by the render-finished semaphore
  ib.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
  ib.newLayout = VK_IMAGE_LAYOUT_PRESENT_SRC_KHR;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, 0, 0, nullptr, 0,
                       nullptr, 1, &ib);
}

std::vector<uint8_t> DisplayPass::read_shown(uint32_t& width, uint32_t& height) {
  width = rect_.width;
  height = rect_.height;
  std::vector<uint32_t> texels(size_t(target_.width) * target_.height);
  display_.download(ctx_, texels.data(), texels.size() * sizeof(uint32_t));
  std::vector<uint8_t> rgb(size_t(width) * height * 3);
  for (uint32_t y = 0; y < height; ++y)
    for (uint32_t x = 0; x < width; ++x) {
      const uint32_t t = texels[size_t(rect_.y + y) * target_.width + rect_.x + x];
      uint8_t c[3] = {uint8_t(t), uint8_t(t >> 8), uint8_t(t >> 16)};
      if (bgra_) std::swap(c[0], c[2]);  // stored B, G, R
      std::copy(c, c + 3, &rgb[(size_t(y) * width + x) * 3]);
    }
  return rgb;
}

}  // namespace pyrolume::preview
