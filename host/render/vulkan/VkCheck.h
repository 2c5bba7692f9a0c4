#pragma once
// VK_CHECK(expr): every Vulkan call whose VkResult matters goes through it, so a
// failure reports the call, the VkResult name and where it happened.
#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>

namespace pyrolume::vk {

struct VulkanError : std::runtime_error {
  explicit VulkanError(const std::string& message, VkResult result = VK_ERROR_UNKNOWN)
      : std::runtime_error(message), result(result) {}
  VkResult result;
};

inline const char* vk_result_name(VkResult r) {
  switch (r) {
#define PYROLUME_VK_RESULT(x) \
  case x: return #x;
    PYROLUME_VK_RESULT(VK_SUCCESS)
    PYROLUME_VK_RESULT(VK_NOT_READY)
    PYROLUME_VK_RESULT(VK_TIMEOUT)
    PYROLUME_VK_RESULT(VK_EVENT_SET)
    PYROLUME_VK_RESULT(VK_EVENT_RESET)
    PYROLUME_VK_RESULT(VK_INCOMPLETE)
    PYROLUME_VK_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    PYROLUME_VK_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    PYROLUME_VK_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    PYROLUME_VK_RESULT(VK_ERROR_DEVICE_LOST)
    PYROLUME_VK_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    PYROLUME_VK_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
    PYROLUME_VK_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
    PYROLUME_VK_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    PYROLUME_VK_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
    PYROLUME_VK_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
    PYROLUME_VK_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
    PYROLUME_VK_RESULT(VK_ERROR_FRAGMENTED_POOL)
    PYROLUME_VK_RESULT(VK_ERROR_UNKNOWN)
    PYROLUME_VK_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
    PYROLUME_VK_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    PYROLUME_VK_RESULT(VK_ERROR_FRAGMENTATION)
    PYROLUME_VK_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
    PYROLUME_VK_RESULT(VK_PIPELINE_COMPILE_REQUIRED)
    PYROLUME_VK_RESULT(VK_ERROR_SURFACE_LOST_KHR)
    PYROLUME_VK_RESULT(VK_ERROR_NATIVE_WINDOW_IN_USE_KHR)
    PYROLUME_VK_RESULT(VK_SUBOPTIMAL_KHR)
    PYROLUME_VK_RESULT(VK_ERROR_OUT_OF_DATE_KHR)
    PYROLUME_VK_RESULT(VK_ERROR_INCOMPATIBLE_DISPLAY_KHR)
    PYROLUME_VK_RESULT(VK_ERROR_VALIDATION_FAILED_EXT)
#undef PYROLUME_VK_RESULT
    default: return "VK_RESULT_UNKNOWN_CODE";
  }
}

// Out of line in spirit: keeps the macro expansion small at every call site.
[[noreturn]] inline void throw_vk_error(const char* expr, VkResult r, const char* file, int line) {
  throw VulkanError(std::string(expr) + " failed: " + vk_result_name(r) + " (" + std::to_string(int(r)) +
                        ") at " + file + ":" + std::to_string(line),
                    r);
}

}  // namespace pyrolume::vk

// Anything but VK_SUCCESS throws: callers that expect VK_INCOMPLETE/VK_TIMEOUT
// handle the result themselves.
#define VK_CHECK(expr)                                                                 \
  do {                                                                                 \
    VkResult pyrolume_vk_r_ = (expr);                                                  \
    if (pyrolume_vk_r_ != VK_SUCCESS)                                                  \
      ::pyrolume::vk::throw_vk_error(#expr, pyrolume_vk_r_, __FILE__, __LINE__);      \
  } while (0)
