#pragma once
// The Vulkan instance, the chosen device and one compute queue; validation and
// debug names; a one-shot command submission helper.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <vector>

#include "render/vulkan/Devices.h"
#include "render/vulkan/Handles.h"
#include "render/vulkan/VkCheck.h"

namespace pyrolume::vk {

class PipelineCache;  // render/vulkan/Pipeline.h

class Context {
 public:
  struct Options {
    int device_index = -1;    // -1: PYROLUME_DEVICE, else the preference order (Devices.h)
    bool validation = false;  // also on when PYROLUME_VALIDATION=1 (and not "0")
    bool sync_validation = true;  // with validation: also synchronization validation
    std::vector<const char*> instance_extensions;  // e.g. surface extensions for the preview
    std::vector<const char*> device_extensions;    // e.g. VK_KHR_swapchain
  };
  // Optional features turned on when the device has them.
  struct Features {
    bool shader_int64 = false;
    bool shader_buffer_int64_atomics = false;
    bool host_query_reset = false;
    // Compute shaders may count a subgroup's lanes (subgroupBallot, subgroupBallotBitCount).
    bool subgroup_ballot = false;
  };

  explicit Context(const Options& options);
  ~Context();
  // The debug messenger holds `this`: not copyable, not movable.
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkInstance instance() const { return instance_.get(); }
  VkPhysicalDevice physical_device() const { return physical_device_; }
  VkDevice device() const { return device_.get(); }
  VkQueue queue() const { return queue_; }
  uint32_t queue_family() const { return queue_family_; }
  const DeviceInfo& info() const { return info_; }
  const VkPhysicalDeviceProperties& properties() const { return properties_; }
  const VkPhysicalDeviceMemoryProperties& memory_properties() const { return memory_properties_; }
  const Features& features() const { return features_; }
  // Largest single allocation the device accepts (maintenance3).
  VkDeviceSize max_allocation_size() const { return max_allocation_size_; }

  bool validation_enabled() const { return validation_enabled_; }
  // Warning + error messages seen by this context's debug messenger.
  uint64_t validation_messages() const { return validation_messages_.load(); }
  // The same, summed over every Context in this process (also counts messages
  // raised while a Context is destroyed, e.g. leaked objects).
  static uint64_t total_validation_messages();

  // Nanoseconds per timestamp tick; 0 when the queue cannot write timestamps.
  double timestamp_period_ns() const { return timestamp_period_ns_; }

  template <typename T>
  void set_name(T handle, const char* name) const {
    vk::set_name(device_.get(), handle, name);
  }

  // Records with `record` into a fresh command buffer, submits it and waits.
  // For uploads, readbacks and one-off work; thread-safe (serialised).
  void submit_and_wait(const std::function<void(VkCommandBuffer)>& record);

  // The pipelines this device made, shared by the sessions that ask for the
  // same one again (render/vulkan/Pipeline.h).
  PipelineCache& pipelines() { return *pipelines_; }

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                       VkDebugUtilsMessageTypeFlagsEXT types,
                                                       const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                       void* user);

  // First: the messenger writes it until the instance is gone.
  std::atomic<uint64_t> validation_messages_{0};
  // Declared in creation order: members are destroyed in reverse.
  UniqueInstance instance_;
  UniqueDebugMessenger messenger_;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  DeviceInfo info_;
  VkPhysicalDeviceProperties properties_{};
  VkPhysicalDeviceMemoryProperties memory_properties_{};
  Features features_;
  VkDeviceSize max_allocation_size_ = 0;
  UniqueDevice device_;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  double timestamp_period_ns_ = 0.0;
  bool validation_enabled_ = false;
  bool debug_utils_ = false;

  std::mutex submit_mutex_;
  UniqueCommandPool command_pool_;
  VkCommandBuffer command_buffer_ = VK_NULL_HANDLE;  // freed with the pool
  UniqueFence fence_;
  // Last: its pipelines go before the device does.
  std::unique_ptr<PipelineCache> pipelines_;
};

// Same as ctx.submit_and_wait(record).
void submit_and_wait(Context& ctx, const std::function<void(VkCommandBuffer)>& record);

}  // namespace pyrolume::vk
