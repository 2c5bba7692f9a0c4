#pragma once
// One small move-only owner per Vulkan handle kind, so nothing is destroyed by
// hand at call sites (hand-written destroy lists leak), plus debug names.
#include <vulkan/vulkan.h>

#include <cstdint>
#include <type_traits>
#include <utility>

namespace pyrolume::vk {

static_assert(sizeof(void*) == 8, "handle traits assume 64-bit (distinct non-dispatchable handle types)");

// Owns one handle; Deleter(handle) destroys it. Holds whatever parent the
// deleter needs (device, instance) by value.
template <typename T, typename Deleter>
class Unique {
 public:
  Unique() = default;
  Unique(T handle, Deleter deleter) : handle_(handle), deleter_(deleter) {}
  ~Unique() { reset(); }
  Unique(const Unique&) = delete;
  Unique& operator=(const Unique&) = delete;
  Unique(Unique&& o) noexcept : handle_(std::exchange(o.handle_, T(VK_NULL_HANDLE))), deleter_(o.deleter_) {}
  Unique& operator=(Unique&& o) noexcept {
    if (this != &o) {
      reset();
      handle_ = std::exchange(o.handle_, T(VK_NULL_HANDLE));
      deleter_ = o.deleter_;
    }
    return *this;
  }

  T get() const { return handle_; }
  explicit operator bool() const { return handle_ != VK_NULL_HANDLE; }
  const Deleter& deleter() const { return deleter_; }
  T release() { return std::exchange(handle_, T(VK_NULL_HANDLE)); }
  void reset() {
    if (handle_ != VK_NULL_HANDLE) deleter_(std::exchange(handle_, T(VK_NULL_HANDLE)));
  }

 private:
  T handle_ = VK_NULL_HANDLE;
  Deleter deleter_{};
};

// Children of a VkDevice: vkDestroyX(device, handle, allocator).
template <typename T, void (*Destroy)(VkDevice, T, const VkAllocationCallbacks*)>
struct DeviceDeleter {
  VkDevice device = VK_NULL_HANDLE;
  void operator()(T h) const { Destroy(device, h, nullptr); }
};

struct InstanceDeleter {
  void operator()(VkInstance h) const { vkDestroyInstance(h, nullptr); }
};
struct DeviceHandleDeleter {
  void operator()(VkDevice h) const { vkDestroyDevice(h, nullptr); }
};
// Extension function: the pointer comes from vkGetInstanceProcAddr.
struct DebugMessengerDeleter {
  VkInstance instance = VK_NULL_HANDLE;
  PFN_vkDestroyDebugUtilsMessengerEXT destroy = nullptr;
  void operator()(VkDebugUtilsMessengerEXT h) const {
    if (destroy) destroy(instance, h, nullptr);
  }
};

using UniqueInstance = Unique<VkInstance, InstanceDeleter>;
using UniqueDebugMessenger = Unique<VkDebugUtilsMessengerEXT, DebugMessengerDeleter>;
using UniqueDevice = Unique<VkDevice, DeviceHandleDeleter>;
using UniqueBuffer = Unique<VkBuffer, DeviceDeleter<VkBuffer, vkDestroyBuffer>>;
using UniqueDeviceMemory = Unique<VkDeviceMemory, DeviceDeleter<VkDeviceMemory, vkFreeMemory>>;
using UniqueImage = Unique<VkImage, DeviceDeleter<VkImage, vkDestroyImage>>;
using UniqueImageView = Unique<VkImageView, DeviceDeleter<VkImageView, vkDestroyImageView>>;
using UniqueBufferView = Unique<VkBufferView, DeviceDeleter<VkBufferView, vkDestroyBufferView>>;
using UniqueSampler = Unique<VkSampler, DeviceDeleter<VkSampler, vkDestroySampler>>;
using UniqueDescriptorSetLayout =
    Unique<VkDescriptorSetLayout, DeviceDeleter<VkDescriptorSetLayout, vkDestroyDescriptorSetLayout>>;
using UniqueDescriptorPool = Unique<VkDescriptorPool, DeviceDeleter<VkDescriptorPool, vkDestroyDescriptorPool>>;
using UniquePipelineLayout = Unique<VkPipelineLayout, DeviceDeleter<VkPipelineLayout, vkDestroyPipelineLayout>>;
using UniquePipeline = Unique<VkPipeline, DeviceDeleter<VkPipeline, vkDestroyPipeline>>;
using UniqueShaderModule = Unique<VkShaderModule, DeviceDeleter<VkShaderModule, vkDestroyShaderModule>>;
using UniqueCommandPool = Unique<VkCommandPool, DeviceDeleter<VkCommandPool, vkDestroyCommandPool>>;
using UniqueFence = Unique<VkFence, DeviceDeleter<VkFence, vkDestroyFence>>;
using UniqueSemaphore = Unique<VkSemaphore, DeviceDeleter<VkSemaphore, vkDestroySemaphore>>;
using UniqueQueryPool = Unique<VkQueryPool, DeviceDeleter<VkQueryPool, vkDestroyQueryPool>>;

// VkObjectType of each handle type, for debug names.
template <typename T>
struct ObjectType;
#define PYROLUME_OBJECT_TYPE(T, E) \
  template <>                      \
  struct ObjectType<T> {           \
    static constexpr VkObjectType value = E; \
  };
PYROLUME_OBJECT_TYPE(VkInstance, VK_OBJECT_TYPE_INSTANCE)
PYROLUME_OBJECT_TYPE(VkPhysicalDevice, VK_OBJECT_TYPE_PHYSICAL_DEVICE)
PYROLUME_OBJECT_TYPE(VkDevice, VK_OBJECT_TYPE_DEVICE)
PYROLUME_OBJECT_TYPE(VkQueue, VK_OBJECT_TYPE_QUEUE)
PYROLUME_OBJECT_TYPE(VkCommandBuffer, VK_OBJECT_TYPE_COMMAND_BUFFER)
PYROLUME_OBJECT_TYPE(VkBuffer, VK_OBJECT_TYPE_BUFFER)
PYROLUME_OBJECT_TYPE(VkDeviceMemory, VK_OBJECT_TYPE_DEVICE_MEMORY)
PYROLUME_OBJECT_TYPE(VkImage, VK_OBJECT_TYPE_IMAGE)
PYROLUME_OBJECT_TYPE(VkImageView, VK_OBJECT_TYPE_IMAGE_VIEW)
PYROLUME_OBJECT_TYPE(VkSampler, VK_OBJECT_TYPE_SAMPLER)
PYROLUME_OBJECT_TYPE(VkDescriptorSetLayout, VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT)
PYROLUME_OBJECT_TYPE(VkDescriptorPool, VK_OBJECT_TYPE_DESCRIPTOR_POOL)
PYROLUME_OBJECT_TYPE(VkDescriptorSet, VK_OBJECT_TYPE_DESCRIPTOR_SET)
PYROLUME_OBJECT_TYPE(VkPipelineLayout, VK_OBJECT_TYPE_PIPELINE_LAYOUT)
PYROLUME_OBJECT_TYPE(VkPipeline, VK_OBJECT_TYPE_PIPELINE)
PYROLUME_OBJECT_TYPE(VkShaderModule, VK_OBJECT_TYPE_SHADER_MODULE)
PYROLUME_OBJECT_TYPE(VkCommandPool, VK_OBJECT_TYPE_COMMAND_POOL)
PYROLUME_OBJECT_TYPE(VkFence, VK_OBJECT_TYPE_FENCE)
PYROLUME_OBJECT_TYPE(VkSemaphore, VK_OBJECT_TYPE_SEMAPHORE)
PYROLUME_OBJECT_TYPE(VkQueryPool, VK_OBJECT_TYPE_QUERY_POOL)
#undef PYROLUME_OBJECT_TYPE

// Names an object through VK_EXT_debug_utils when the device's Context enabled
// it; otherwise does nothing. Defined in Context.cpp.
void set_object_name(VkDevice device, VkObjectType type, uint64_t handle, const char* name);

template <typename T>
void set_name(VkDevice device, T handle, const char* name) {
  uint64_t raw;
  if constexpr (std::is_pointer_v<T>)
    raw = reinterpret_cast<uint64_t>(handle);
  else
    raw = static_cast<uint64_t>(handle);
  set_object_name(device, ObjectType<T>::value, raw, name);
}

template <typename T, typename D>
void set_name(VkDevice device, const Unique<T, D>& handle, const char* name) {
  set_name(device, handle.get(), name);
}

}  // namespace pyrolume::vk
