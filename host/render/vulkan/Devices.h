#pragma once
// Which Vulkan devices exist and which one pyrolume renders on.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>
#include <vector>

#include "render/vulkan/VkCheck.h"
#include "util/Error.h"

namespace pyrolume::vk {

// No Vulkan driver or no device: NoDeviceError (util/Error.h) whose message
// is one line that points to --backend cpu.
NoDeviceError no_device_error(const std::string& detail);

struct DeviceInfo {
  uint32_t index = 0;  // position in vkEnumeratePhysicalDevices
  std::string name;
  VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
  std::string type_name;  // "discrete", "integrated", "virtual", "cpu", "other"
  uint32_t api_version = 0;
  std::string driver_name;  // e.g. "llvmpipe", "NVIDIA"; empty before Vulkan 1.2
  uint64_t device_local_bytes = 0;  // sum of DEVICE_LOCAL heaps
};

// Enumerates with a short-lived instance of its own. Throws NoDeviceError when
// there is no driver or no device.
std::vector<DeviceInfo> list_devices();
// Same, on an existing instance (the Context uses it so indices agree).
std::vector<DeviceInfo> list_devices(VkInstance instance);
DeviceInfo describe_device(VkPhysicalDevice device, uint32_t index);

const char* device_type_name(VkPhysicalDeviceType type);
std::string api_version_string(uint32_t version);  // "1.3.230"

// For `pyrolume devices`: one line per device, "*" and "(default)" on `chosen`.
std::string format_device_list(const std::vector<DeviceInfo>& devices, int chosen);

// requested >= 0: that index (else InputError naming how many exist).
// requested < 0: PYROLUME_DEVICE if set (validated the same way), else the
// first discrete GPU, then integrated, virtual, CPU; ties by index.
// Empty list: NoDeviceError.
int choose_device(const std::vector<DeviceInfo>& devices, int requested);

}  // namespace pyrolume::vk
