#include "render/vulkan/Devices.h"

// Vulkan structs are written {.sType = ...}: the rest is zero by design.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "render/vulkan/Handles.h"
#include "util/Error.h"

namespace pyrolume::vk {

NoDeviceError no_device_error(const std::string& detail) {
  return NoDeviceError("no Vulkan device available (" + detail +
                       "); install a Vulkan driver (e.g. mesa-vulkan-drivers) or use --backend cpu");
}

const char* device_type_name(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return "cpu";
    default: return "other";
  }
}

std::string api_version_string(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

DeviceInfo describe_device(VkPhysicalDevice device, uint32_t index) {
  VkPhysicalDeviceProperties props{};
  vkGetPhysicalDeviceProperties(device, &props);
  DeviceInfo info;
  info.index = index;
  info.name = props.deviceName;
  info.type = props.deviceType;
  info.type_name = device_type_name(props.deviceType);
  info.api_version = props.apiVersion;
  // Driver properties are core in 1.2; the instance is 1.1+ so properties2 exists.
  if (props.apiVersion >= VK_API_VERSION_1_2) {
    VkPhysicalDeviceDriverProperties driver{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 props2{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &driver};
    vkGetPhysicalDeviceProperties2(device, &props2);
    info.driver_name = driver.driverName;
  }
  VkPhysicalDeviceMemoryProperties mem{};
  vkGetPhysicalDeviceMemoryProperties(device, &mem);
  for (uint32_t i = 0; i < mem.memoryHeapCount; ++i)
    if (mem.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) info.device_local_bytes += mem.memoryHeaps[i].size;
  return info;
}

std::vector<DeviceInfo> list_devices(VkInstance instance) {
  uint32_t count = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  if (count) VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
  std::vector<DeviceInfo> infos;
  for (uint32_t i = 0; i < count; ++i) infos.push_back(describe_device(devices[i], i));
  if (infos.empty()) throw no_device_error("the Vulkan loader found no physical device");
  return infos;
}

std::vector<DeviceInfo> list_devices() {
  uint32_t loader_version = VK_API_VERSION_1_0;
  if (vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS || loader_version < VK_API_VERSION_1_1)
    throw no_device_error("the Vulkan loader is older than 1.1");
  VkApplicationInfo app{.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "pyrolume devices";
  app.apiVersion = loader_version >= VK_API_VERSION_1_3 ? VK_API_VERSION_1_3 : loader_version;
  VkInstanceCreateInfo ci{.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ci.pApplicationInfo = &app;
  // Portability drivers (MoltenVK) are listed only when asked for.
  uint32_t ext_count = 0;
  vkEnumerateInstanceExtensionProperties(nullptr, &ext_count, nullptr);
  std::vector<VkExtensionProperties> exts(ext_count);
  vkEnumerateInstanceExtensionProperties(nullptr, &ext_count, exts.data());
  const char* portability = VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME;
  for (auto& e : exts)
    if (std::string(e.extensionName) == portability) {
      ci.enabledExtensionCount = 1;
      ci.ppEnabledExtensionNames = &portability;
      ci.flags |= VK_INSTANCE_CREATE_ENUMERATE_PORTABILITY_BIT_KHR;
    }
  VkInstance raw = VK_NULL_HANDLE;
  VkResult r = vkCreateInstance(&ci, nullptr, &raw);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER || r == VK_ERROR_INITIALIZATION_FAILED)
    throw no_device_error(std::string("vkCreateInstance: ") + vk_result_name(r));
  VK_CHECK(r);
  UniqueInstance instance(raw, {});
  return list_devices(instance.get());
}

std::string format_device_list(const std::vector<DeviceInfo>& devices, int chosen) {
  std::ostringstream out;
  for (const DeviceInfo& d : devices) {
    char mem[32];
    std::snprintf(mem, sizeof mem, "%.1f GiB", double(d.device_local_bytes) / (1024.0 * 1024.0 * 1024.0));
    out << (int(d.index) == chosen ? "* " : "  ") << d.index << ": " << d.name << " | " << d.type_name
        << " | Vulkan " << api_version_string(d.api_version) << " | " << mem;
    if (!d.driver_name.empty()) out << " | " << d.driver_name;
    if (int(d.index) == chosen) out << " (default)";
    out << "\n";
  }
  return out.str();
}

namespace {

int preference_rank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

std::string range_text(size_t n) {
  return std::to_string(n) + (n == 1 ? " Vulkan device exists (index 0)" : " Vulkan devices exist (indices 0.." +
                                                                               std::to_string(n - 1) + ")") +
         "; run `pyrolume devices` to list them";
}

}  // namespace

int choose_device(const std::vector<DeviceInfo>& devices, int requested) {
  if (devices.empty()) throw no_device_error("the Vulkan loader found no physical device");
  if (requested >= 0) {
    if (size_t(requested) >= devices.size())
      throw InputError("--device " + std::to_string(requested) + ": no such device; " + range_text(devices.size()));
    return requested;
  }
  if (const char* env = std::getenv("PYROLUME_DEVICE"); env && *env) {
    char* end = nullptr;
    long v = std::strtol(env, &end, 10);
    if (*end != '\0' || v < 0 || size_t(v) >= devices.size())
      throw InputError(std::string("PYROLUME_DEVICE=") + env + ": no such device; " + range_text(devices.size()));
    return int(v);
  }
  size_t best = 0;
  for (size_t i = 1; i < devices.size(); ++i)
    if (preference_rank(devices[i].type) < preference_rank(devices[best].type)) best = i;
  return int(best);
}

}  // namespace pyrolume::vk
