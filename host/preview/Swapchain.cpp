#include "preview/Swapchain.h"

// Vulkan structs are written {.sType = ...}: the rest is zero by design.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

#include <algorithm>
#include <string>

#include "render/vulkan/VkCheck.h"

namespace pyrolume::preview {
namespace {

// 8-bit RGBA formats whose texels are one packed uint32, the display shader's
// output. UNORM and SRGB present the same stored bytes (the copy does no
// conversion), so both work; the display shader always sRGB-encodes.
struct FormatChoice {
  VkFormat format;
  bool bgra;
};
constexpr FormatChoice kFormats[] = {
    {VK_FORMAT_B8G8R8A8_UNORM, true},         {VK_FORMAT_R8G8B8A8_UNORM, false},
    {VK_FORMAT_B8G8R8A8_SRGB, true},          {VK_FORMAT_R8G8B8A8_SRGB, false},
    {VK_FORMAT_A8B8G8R8_UNORM_PACK32, false}, {VK_FORMAT_A8B8G8R8_SRGB_PACK32, false},
};

}  // namespace

Swapchain::Swapchain(vk::Context& ctx, VkSurfaceKHR surface) : ctx_(ctx), surface_(surface) {}

bool Swapchain::recreate(VkExtent2D framebuffer) {
  VkPhysicalDevice pd = ctx_.physical_device();
  VkSurfaceCapabilitiesKHR caps{};
  VK_CHECK(vkGetPhysicalDeviceSurfaceCapabilitiesKHR(pd, surface_, &caps));

  // Where the surface defines its size, the swapchain must match it exactly.
  VkExtent2D extent = caps.currentExtent;
  if (extent.width == 0xFFFFFFFFu) {
    extent.width = std::clamp(framebuffer.width, caps.minImageExtent.width, caps.maxImageExtent.width);
    extent.height = std::clamp(framebuffer.height, caps.minImageExtent.height, caps.maxImageExtent.height);
  }
  if (extent.width == 0 || extent.height == 0 || framebuffer.width == 0 || framebuffer.height == 0) {
    render_finished_.clear();
    images_.clear();
    swapchain_.reset();
    extent_ = {0, 0};
    return false;
  }

  if (!(caps.supportedUsageFlags & VK_IMAGE_USAGE_TRANSFER_DST_BIT))
    throw NoDisplayError("the display's swapchain images cannot be copied to (no TRANSFER_DST usage)");

  uint32_t nformats = 0;
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(pd, surface_, &nformats, nullptr));
  std::vector<VkSurfaceFormatKHR> formats(nformats);
  VK_CHECK(vkGetPhysicalDeviceSurfaceFormatsKHR(pd, surface_, &nformats, formats.data()));
  const VkSurfaceFormatKHR* chosen = nullptr;
  for (const FormatChoice& want : kFormats) {
    for (const VkSurfaceFormatKHR& f : formats)
      if (f.format == want.format && f.colorSpace == VK_COLOR_SPACE_SRGB_NONLINEAR_KHR) {
        chosen = &f;
        bgra_ = want.bgra;
        break;
      }
    if (chosen) break;
  }
  if (!chosen)
    throw NoDisplayError("the display offers no 8-bit RGBA/BGRA sRGB swapchain format (" +
                     std::to_string(nformats) + " formats)");
  format_ = chosen->format;

  // Mailbox or immediate: the adaptive sample count, not the display's refresh,
  // paces the loop. FIFO is the one mode every implementation has.
  uint32_t nmodes = 0;
  VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(pd, surface_, &nmodes, nullptr));
  std::vector<VkPresentModeKHR> modes(nmodes);
  VK_CHECK(vkGetPhysicalDeviceSurfacePresentModesKHR(pd, surface_, &nmodes, modes.data()));
  VkPresentModeKHR mode = VK_PRESENT_MODE_FIFO_KHR;
  for (VkPresentModeKHR m : {VK_PRESENT_MODE_MAILBOX_KHR, VK_PRESENT_MODE_IMMEDIATE_KHR})
    if (std::find(modes.begin(), modes.end(), m) != modes.end()) {
      mode = m;
      break;
    }

  uint32_t count = caps.minImageCount + 1;
  if (caps.maxImageCount > 0) count = std::min(count, caps.maxImageCount);

  VkCompositeAlphaFlagBitsKHR alpha = VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR;
  for (VkCompositeAlphaFlagBitsKHR a : {VK_COMPOSITE_ALPHA_OPAQUE_BIT_KHR, VK_COMPOSITE_ALPHA_INHERIT_BIT_KHR,
                                        VK_COMPOSITE_ALPHA_PRE_MULTIPLIED_BIT_KHR,
                                        VK_COMPOSITE_ALPHA_POST_MULTIPLIED_BIT_KHR})
    if (caps.supportedCompositeAlpha & a) {
      alpha = a;
      break;
    }

  VkSwapchainCreateInfoKHR ci{.sType = VK_STRUCTURE_TYPE_SWAPCHAIN_CREATE_INFO_KHR};
  ci.surface = surface_;
  ci.minImageCount = count;
  ci.imageFormat = chosen->format;
  ci.imageColorSpace = chosen->colorSpace;
  ci.imageExtent = extent;
  ci.imageArrayLayers = 1;
  ci.imageUsage = VK_IMAGE_USAGE_TRANSFER_DST_BIT;
  ci.imageSharingMode = VK_SHARING_MODE_EXCLUSIVE;  // one queue renders and presents
  ci.preTransform = caps.currentTransform;
  ci.compositeAlpha = alpha;
  ci.presentMode = mode;
  ci.clipped = VK_TRUE;
  ci.oldSwapchain = swapchain_.get();
  VkSwapchainKHR raw = VK_NULL_HANDLE;
  VK_CHECK(vkCreateSwapchainKHR(ctx_.device(), &ci, nullptr, &raw));
  // The old swapchain (if any) is retired by the new one's creation; the caller
  // made the device idle, so it can go now.
  swapchain_ = UniqueSwapchain(raw, {ctx_.device()});
  ctx_.set_name(raw, "preview swapchain");
  extent_ = extent;

  uint32_t nimages = 0;
  VK_CHECK(vkGetSwapchainImagesKHR(ctx_.device(), raw, &nimages, nullptr));
  images_.resize(nimages);
  VK_CHECK(vkGetSwapchainImagesKHR(ctx_.device(), raw, &nimages, images_.data()));

  render_finished_.clear();
  for (uint32_t i = 0; i < nimages; ++i) {
    VkSemaphoreCreateInfo sci{.sType = VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore s = VK_NULL_HANDLE;
    VK_CHECK(vkCreateSemaphore(ctx_.device(), &sci, nullptr, &s));
    render_finished_.emplace_back(s, vk::DeviceDeleter<VkSemaphore, vkDestroySemaphore>{ctx_.device()});
    ctx_.set_name(s, "preview render finished");
    ctx_.set_name(images_[i], "preview swapchain image");
  }
  return true;
}

}  // namespace pyrolume::preview
