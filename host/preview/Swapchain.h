#pragma once
// The window's swapchain: format, extent and present mode chosen for a
// compute-only renderer that copies finished pixels into the images.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <vector>

#include "preview/PreviewHandles.h"
#include "render/vulkan/Context.h"

namespace pyrolume::preview {

class Swapchain {
 public:
  Swapchain(vk::Context& ctx, VkSurfaceKHR surface);

  // (Re)create for a framebuffer of `framebuffer` pixels. The device must be
  // idle. Returns false (and holds no swapchain) when the surface has no area,
  // as for a minimised window.
  bool recreate(VkExtent2D framebuffer);

  VkSwapchainKHR get() const { return swapchain_.get(); }
  explicit operator bool() const { return bool(swapchain_); }
  VkExtent2D extent() const { return extent_; }
  VkFormat format() const { return format_; }
  // The format stores B, G, R, A in memory (B8G8R8A8_*), not R, G, B, A.
  bool bgra() const { return bgra_; }
  uint32_t image_count() const { return uint32_t(images_.size()); }
  VkImage image(uint32_t i) const { return images_[i]; }
  // Signalled by the frame's submit, waited on by its present: one per image,
  // since a present's wait semaphore may be in use until that image comes back.
  VkSemaphore render_finished(uint32_t i) const { return render_finished_[i].get(); }

 private:
  vk::Context& ctx_;
  VkSurfaceKHR surface_;
  UniqueSwapchain swapchain_;
  std::vector<VkImage> images_;  // owned by the swapchain
  std::vector<vk::UniqueSemaphore> render_finished_;
  VkExtent2D extent_{0, 0};
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  bool bgra_ = false;
};

}  // namespace pyrolume::preview
