#pragma once
// Owners for what only the preview creates: the GLFW library and window, the
// window's Vulkan surface and its swapchain. Same pattern as render/vulkan/Handles.h.
#include <vulkan/vulkan.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <memory>
#include <stdexcept>

#include "render/vulkan/Handles.h"

namespace pyrolume::preview {

// This machine cannot show the window (no display, no surface support, no
// usable swapchain): the CLI prints one line suggesting `render`, exit status 2.
struct NoDisplayError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// glfwInit ... glfwTerminate. Construct with ok() checked: glfwInit fails
// without a display.
class GlfwLibrary {
 public:
  GlfwLibrary() : ok_(glfwInit() == GLFW_TRUE) {}
  ~GlfwLibrary() {
    if (ok_) glfwTerminate();
  }
  GlfwLibrary(const GlfwLibrary&) = delete;
  GlfwLibrary& operator=(const GlfwLibrary&) = delete;
  bool ok() const { return ok_; }

 private:
  bool ok_;
};

struct WindowDeleter {
  void operator()(GLFWwindow* w) const { glfwDestroyWindow(w); }
};
using UniqueWindow = std::unique_ptr<GLFWwindow, WindowDeleter>;

struct SurfaceDeleter {
  VkInstance instance = VK_NULL_HANDLE;
  void operator()(VkSurfaceKHR h) const { vkDestroySurfaceKHR(instance, h, nullptr); }
};
using UniqueSurface = vk::Unique<VkSurfaceKHR, SurfaceDeleter>;
using UniqueSwapchain = vk::Unique<VkSwapchainKHR, vk::DeviceDeleter<VkSwapchainKHR, vkDestroySwapchainKHR>>;

}  // namespace pyrolume::preview

namespace pyrolume::vk {
// Debug names for the preview's own handle kinds (Handles.h lists the rest).
template <>
struct ObjectType<VkSurfaceKHR> {
  static constexpr VkObjectType value = VK_OBJECT_TYPE_SURFACE_KHR;
};
template <>
struct ObjectType<VkSwapchainKHR> {
  static constexpr VkObjectType value = VK_OBJECT_TYPE_SWAPCHAIN_KHR;
};
}  // namespace pyrolume::vk
