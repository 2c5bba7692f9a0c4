#include "render/vulkan/Context.h"

// Vulkan structs are written {.sType = ...}: the rest is zero by design.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "render/vulkan/Pipeline.h"

namespace pyrolume::vk {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::atomic<uint64_t> g_total_validation_messages{0};

// Devices whose Context enabled VK_EXT_debug_utils, with the naming function.
// A small registry rather than one global pointer: only devices created from
// an instance with the extension may be named.
std::mutex g_namer_mutex;
std::vector<std::pair<VkDevice, PFN_vkSetDebugUtilsObjectNameEXT>> g_namers;

bool env_flag(const char* name) {
  const char* v = std::getenv(name);
  return v && *v && std::strcmp(v, "0") != 0;
}

bool has_extension(const std::vector<VkExtensionProperties>& exts, const char* name) {
  return std::any_of(exts.begin(), exts.end(), [&](const auto& e) { return std::strcmp(e.extensionName, name) == 0; });
}

std::vector<VkExtensionProperties> instance_extensions(const char* layer) {
  uint32_t n = 0;
  vkEnumerateInstanceExtensionProperties(layer, &n, nullptr);
  std::vector<VkExtensionProperties> exts(n);
  if (n) vkEnumerateInstanceExtensionProperties(layer, &n, exts.data());
  exts.resize(n);
  return exts;
}

bool has_layer(const char* name) {
  uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  if (n) vkEnumerateInstanceLayerProperties(&n, layers.data());
  layers.resize(n);
  return std::any_of(layers.begin(), layers.end(), [&](const auto& l) { return std::strcmp(l.layerName, name) == 0; });
}

}  // namespace

void set_object_name(VkDevice device, VkObjectType type, uint64_t handle, const char* name) {
  if (!device || !handle || !name) return;
  PFN_vkSetDebugUtilsObjectNameEXT fn = nullptr;
  {
    std::lock_guard lock(g_namer_mutex);
    for (auto& [d, f] : g_namers)
      if (d == device) fn = f;
  }
  if (!fn) return;
  VkDebugUtilsObjectNameInfoEXT info{.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
  info.objectType = type;
  info.objectHandle = handle;
  info.pObjectName = name;
  fn(device, &info);  // names are a debugging aid: a failure is not worth an exception
}

uint64_t Context::total_validation_messages() { return g_total_validation_messages.load(); }

VKAPI_ATTR VkBool32 VKAPI_CALL Context::debug_callback(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                       VkDebugUtilsMessageTypeFlagsEXT types,
                                                       const VkDebugUtilsMessengerCallbackDataEXT* data,
                                                       void* user) {
  if (!(severity & (VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT)))
    return VK_FALSE;
  std::string line = data && data->pMessage ? data->pMessage : "(no message)";
  std::replace(line.begin(), line.end(), '\n', ' ');
  // GENERAL-only messages come from the loader (e.g. no driver manifest): they
  // say nothing about our API use, and the error that follows already explains
  // (errors are one line). VK_LOADER_DEBUG=all shows the loader's own log.
  if (!(types & ~VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT)) return VK_FALSE;
  std::fprintf(stderr, "vulkan validation: %s\n", line.c_str());
  static_cast<Context*>(user)->validation_messages_++;
  g_total_validation_messages++;
  return VK_FALSE;
}

Context::Context(const Options& options) {
  // --- instance ---
  uint32_t loader_version = VK_API_VERSION_1_0;
  if (vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS || loader_version < VK_API_VERSION_1_1)
    throw no_device_error("the Vulkan loader is older than 1.1");
  const uint32_t api = std::min<uint32_t>(VK_API_VERSION_1_3, loader_version);

  std::vector<const char*> layers;
  std::vector<const char*> extensions = options.instance_extensions;
  const auto available = instance_extensions(nullptr);
  bool want_validation = options.validation || env_flag("PYROLUME_VALIDATION");
  if (want_validation) {
    if (has_layer(kValidationLayer)) {
      layers.push_back(kValidationLayer);
      validation_enabled_ = true;
    } else {
      std::fprintf(stderr,
                   "pyrolume: warning: Vulkan validation requested but %s is not installed "
                   "(package vulkan-validationlayers); continuing without it\n",
                   kValidationLayer);
    }
  }
  debug_utils_ = has_extension(available, VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  if (debug_utils_) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  VkInstanceCreateInfo ici{.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  // Portability drivers (MoltenVK) are only enumerated when asked for.
  if (has_extension(available, VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME)) {
    extensions.push_back(VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME);
    ici.flags |= VK_INSTANCE_CREATE_ENUMERATE_PORTABILITY_BIT_KHR;
  }

  VkDebugUtilsMessengerCreateInfoEXT mci{.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  mci.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  mci.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  mci.pfnUserCallback = &Context::debug_callback;
  mci.pUserData = this;

  // Synchronization validation catches missing barriers between passes, the
  // kind of bug that only shows on a real GPU.
  VkValidationFeatureEnableEXT sync = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT vfeatures{.sType = VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  vfeatures.enabledValidationFeatureCount = 1;
  vfeatures.pEnabledValidationFeatures = &sync;

  const void* chain = nullptr;
  if (validation_enabled_ && debug_utils_) {
    // Chained into vkCreateInstance too, so instance creation/destruction is covered.
    chain = &mci;
    if (options.sync_validation &&
        has_extension(instance_extensions(kValidationLayer), VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME)) {
      extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
      vfeatures.pNext = &mci;
      chain = &vfeatures;
    }
  }

  VkApplicationInfo app{.sType = VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "pyrolume";
  app.pEngineName = "pyrolume";
  app.apiVersion = api;
  ici.pNext = chain;
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = uint32_t(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  ici.enabledExtensionCount = uint32_t(extensions.size());
  ici.ppEnabledExtensionNames = extensions.data();
  VkInstance raw_instance = VK_NULL_HANDLE;
  VkResult r = vkCreateInstance(&ici, nullptr, &raw_instance);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER || r == VK_ERROR_INITIALIZATION_FAILED)
    throw no_device_error(std::string("vkCreateInstance: ") + vk_result_name(r));
  VK_CHECK(r);
  instance_ = UniqueInstance(raw_instance, {});

  if (validation_enabled_ && debug_utils_) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance(), "vkCreateDebugUtilsMessengerEXT"));
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance(), "vkDestroyDebugUtilsMessengerEXT"));
    VkDebugUtilsMessengerEXT m = VK_NULL_HANDLE;
    VK_CHECK(create(instance(), &mci, nullptr, &m));
    messenger_ = UniqueDebugMessenger(m, {instance(), destroy});
  }

  // --- physical device ---
  std::vector<DeviceInfo> infos = list_devices(instance());
  int chosen = choose_device(infos, options.device_index);
  uint32_t count = 0;
  VK_CHECK(vkEnumeratePhysicalDevices(instance(), &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  VK_CHECK(vkEnumeratePhysicalDevices(instance(), &count, devices.data()));
  physical_device_ = devices.at(size_t(chosen));
  info_ = infos[size_t(chosen)];
  vkGetPhysicalDeviceProperties(physical_device_, &properties_);
  vkGetPhysicalDeviceMemoryProperties(physical_device_, &memory_properties_);
  if (properties_.apiVersion < VK_API_VERSION_1_2)
    throw VulkanError("Vulkan device " + std::to_string(chosen) + " (" + info_.name + ") supports only Vulkan " +
                      api_version_string(properties_.apiVersion) +
                      "; pyrolume needs 1.2: choose another with --device or use --backend cpu");
  VkPhysicalDeviceSubgroupProperties subgroup{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceMaintenance3Properties m3{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES,
                                            .pNext = &subgroup};
  VkPhysicalDeviceProperties2 props2{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, .pNext = &m3};
  vkGetPhysicalDeviceProperties2(physical_device_, &props2);
  max_allocation_size_ = m3.maxMemoryAllocationSize;
  features_.subgroup_ballot = (subgroup.supportedStages & VK_SHADER_STAGE_COMPUTE_BIT) &&
                              (subgroup.supportedOperations & VK_SUBGROUP_FEATURE_BALLOT_BIT);

  // --- queue family: prefer graphics+compute (the preview presents from it), else any compute ---
  uint32_t nfam = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &nfam, nullptr);
  std::vector<VkQueueFamilyProperties> families(nfam);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_device_, &nfam, families.data());
  int family = -1;
  for (uint32_t i = 0; i < nfam && family < 0; ++i)
    if ((families[i].queueFlags & (VK_QUEUE_COMPUTE_BIT | VK_QUEUE_GRAPHICS_BIT)) ==
        (VK_QUEUE_COMPUTE_BIT | VK_QUEUE_GRAPHICS_BIT))
      family = int(i);
  for (uint32_t i = 0; i < nfam && family < 0; ++i)
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) family = int(i);
  if (family < 0) throw VulkanError("Vulkan device " + info_.name + " has no compute queue; use --backend cpu");
  queue_family_ = uint32_t(family);
  if (families[queue_family_].timestampValidBits > 0) timestamp_period_ns_ = properties_.limits.timestampPeriod;

  // --- logical device ---
  VkPhysicalDeviceVulkan12Features have12{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceFeatures2 have{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &have12};
  vkGetPhysicalDeviceFeatures2(physical_device_, &have);
  VkPhysicalDeviceVulkan12Features want12{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  VkPhysicalDeviceFeatures2 want{.sType = VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, .pNext = &want12};
  want.features.shaderInt64 = have.features.shaderInt64;
  want12.shaderBufferInt64Atomics = have12.shaderBufferInt64Atomics;
  want12.hostQueryReset = have12.hostQueryReset;
  features_.shader_int64 = want.features.shaderInt64;
  features_.shader_buffer_int64_atomics = want12.shaderBufferInt64Atomics;
  features_.host_query_reset = want12.hostQueryReset;

  uint32_t next = 0;
  VK_CHECK(vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &next, nullptr));
  std::vector<VkExtensionProperties> dev_exts(next);
  VK_CHECK(vkEnumerateDeviceExtensionProperties(physical_device_, nullptr, &next, dev_exts.data()));
  std::vector<const char*> device_extensions = options.device_extensions;
  // The spec requires enabling it where the device has it (MoltenVK).
  if (has_extension(dev_exts, "VK_KHR_portability_subset")) device_extensions.push_back("VK_KHR_portability_subset");

  float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{.sType = VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = queue_family_;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  VkDeviceCreateInfo dci{.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, .pNext = &want};
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = uint32_t(device_extensions.size());
  dci.ppEnabledExtensionNames = device_extensions.data();
  VkDevice raw_device = VK_NULL_HANDLE;
  VK_CHECK(vkCreateDevice(physical_device_, &dci, nullptr, &raw_device));
  device_ = UniqueDevice(raw_device, {});
  vkGetDeviceQueue(device(), queue_family_, 0, &queue_);

  // --- one-shot submission ---
  VkCommandPoolCreateInfo pci{.sType = VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pci.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pci.queueFamilyIndex = queue_family_;
  VkCommandPool pool = VK_NULL_HANDLE;
  VK_CHECK(vkCreateCommandPool(device(), &pci, nullptr, &pool));
  command_pool_ = UniqueCommandPool(pool, {device()});
  VkCommandBufferAllocateInfo cai{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  cai.commandPool = pool;
  cai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  cai.commandBufferCount = 1;
  VK_CHECK(vkAllocateCommandBuffers(device(), &cai, &command_buffer_));
  VkFenceCreateInfo fci{.sType = VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  VK_CHECK(vkCreateFence(device(), &fci, nullptr, &fence));
  fence_ = UniqueFence(fence, {device()});

  // Last, so that nothing after it can throw and leave a stale registry entry.
  if (debug_utils_) {
    auto fn = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
        vkGetInstanceProcAddr(instance(), "vkSetDebugUtilsObjectNameEXT"));
    if (fn) {
      std::lock_guard lock(g_namer_mutex);
      g_namers.emplace_back(device(), fn);
    }
  }
  set_name(device(), "pyrolume device");
  set_name(queue_, "pyrolume compute queue");
  set_name(pool, "one-shot command pool");
  set_name(command_buffer_, "one-shot command buffer");
  set_name(fence, "one-shot fence");
  pipelines_ = std::make_unique<PipelineCache>(*this);
}

Context::~Context() {
  if (device_) {
    vkDeviceWaitIdle(device());
    std::lock_guard lock(g_namer_mutex);
    std::erase_if(g_namers, [&](const auto& p) { return p.first == device(); });
  }
}

void Context::submit_and_wait(const std::function<void(VkCommandBuffer)>& record) {
  std::lock_guard lock(submit_mutex_);
  VK_CHECK(vkResetCommandBuffer(command_buffer_, VK_COMMAND_BUFFER_RESET_RELEASE_RESOURCES_BIT));
  VkCommandBufferBeginInfo bi{.sType = VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  VK_CHECK(vkBeginCommandBuffer(command_buffer_, &bi));
  record(command_buffer_);
  VK_CHECK(vkEndCommandBuffer(command_buffer_));
  VkSubmitInfo si{.sType = VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &command_buffer_;
  VkFence fence = fence_.get();
  VK_CHECK(vkResetFences(device(), 1, &fence));
  VK_CHECK(vkQueueSubmit(queue_, 1, &si, fence));
  VK_CHECK(vkWaitForFences(device(), 1, &fence, VK_TRUE, UINT64_MAX));
}

void submit_and_wait(Context& ctx, const std::function<void(VkCommandBuffer)>& record) { ctx.submit_and_wait(record); }

}  // namespace pyrolume::vk
