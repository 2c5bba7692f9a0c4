#pragma once
// Accumulation -> window: tonemaps the progressive mean into 8-bit pixels in the
// swapchain's byte order (shaders/preview_display.comp) and copies them into a
// swapchain image. The same pixels can be read back: what the window shows.
#include <vulkan/vulkan.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "render/vulkan/Context.h"
#include "render/vulkan/Memory.h"
#include "render/vulkan/Pipeline.h"
#include "scene/Scene.h"

namespace pyrolume::preview {

// Where the render image sits in a window of `target` pixels: as large as fits,
// aspect kept, centred (letterboxed).
struct ImageRect {
  uint32_t x = 0, y = 0, width = 0, height = 0;
};
inline ImageRect fit_image(uint32_t image_w, uint32_t image_h, uint32_t target_w, uint32_t target_h) {
  ImageRect r;
  if (!image_w || !image_h || !target_w || !target_h) return r;
  // Compare aspect ratios exactly in integers: the common case (window the
  // size of the image) must map 1:1 with no rounding.
  if (uint64_t(target_w) * image_h <= uint64_t(target_h) * image_w) {
    r.width = target_w;
    r.height = uint32_t(std::max<uint64_t>(1, (uint64_t(target_w) * image_h + image_w / 2) / image_w));
  } else {
    r.height = target_h;
    r.width = uint32_t(std::max<uint64_t>(1, (uint64_t(target_h) * image_w + image_h / 2) / image_h));
  }
  r.width = std::min(r.width, target_w);
  r.height = std::min(r.height, target_h);
  r.x = (target_w - r.width) / 2;
  r.y = (target_h - r.height) / 2;
  return r;
}

class DisplayPass {
 public:
  // accum: RenderSession::accumulation() of an image_w × image_h render;
  // accum_bytes: its AccumTexels' part (RenderSession::accumulation_texel_bytes).
  DisplayPass(vk::Context& ctx, const vk::Buffer& accum, VkDeviceSize accum_bytes, uint32_t image_w, uint32_t image_h);

  // (Re)allocate the display buffer for a target (swapchain) size. The device must be idle.
  void resize(VkExtent2D target, bool bgra);

  // Record: mean = Σ L / spp, × 2^exposure, through the view transform
  // (shaders/shared/view_transform.h, as PNG output) into the display buffer,
  // then copy it into `image` and leave that in PRESENT_SRC layout.
  // `image` must be UNDEFINED or PRESENT_SRC (its contents are discarded).
  void record(VkCommandBuffer cmd, int spp, double exposure_stops, ViewTransform view, VkImage image);

  // What the last recorded frame showed inside the image rect, as RGB bytes
  // (sRGB-encoded), row 0 = top. Waits for earlier submitted work.
  std::vector<uint8_t> read_shown(uint32_t& width, uint32_t& height);

  ImageRect rect() const { return rect_; }

 private:
  vk::Context& ctx_;
  uint32_t image_w_, image_h_;
  vk::ComputePipeline pipeline_;
  vk::DescriptorSet set_;
  vk::Buffer display_;  // one packed uint32 per target pixel
  VkExtent2D target_{0, 0};
  ImageRect rect_;
  bool bgra_ = false;
};

}  // namespace pyrolume::preview
