#include "render/vulkan/Pipeline.h"

// Vulkan structs are written {.sType = ...}: the rest is zero by design.
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"

#include <map>

#include "render/vulkan/Spirv.h"

namespace pyrolume::vk {

ComputePipeline::ComputePipeline(Context& ctx, const std::vector<uint32_t>& spirv,
                                 const std::vector<Binding>& bindings, uint32_t push_constant_bytes,
                                 const std::vector<std::pair<uint32_t, uint32_t>>& specialization,
                                 const char* debug_name)
    : bindings_(bindings), push_constant_bytes_(push_constant_bytes), name_(debug_name ? debug_name : "compute") {
  const VkDevice dev = ctx.device();
  if (spirv.empty()) throw VulkanError("ComputePipeline " + name_ + ": empty SPIR-V");

  std::vector<VkDescriptorSetLayoutBinding> lb;
  for (const Binding& b : bindings) lb.push_back({b.binding, b.type, b.count, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
  VkDescriptorSetLayoutCreateInfo sli{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  sli.bindingCount = uint32_t(lb.size());
  sli.pBindings = lb.data();
  VkDescriptorSetLayout sl = VK_NULL_HANDLE;
  VK_CHECK(vkCreateDescriptorSetLayout(dev, &sli, nullptr, &sl));
  set_layout_ = UniqueDescriptorSetLayout(sl, {dev});
  ctx.set_name(sl, (name_ + " set layout").c_str());

  VkPushConstantRange pcr{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_constant_bytes};
  VkPipelineLayoutCreateInfo pli{.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pli.setLayoutCount = 1;
  pli.pSetLayouts = &sl;
  pli.pushConstantRangeCount = push_constant_bytes ? 1 : 0;
  pli.pPushConstantRanges = &pcr;
  VkPipelineLayout pl = VK_NULL_HANDLE;
  VK_CHECK(vkCreatePipelineLayout(dev, &pli, nullptr, &pl));
  layout_ = UniquePipelineLayout(pl, {dev});
  ctx.set_name(pl, (name_ + " layout").c_str());

  // The module is only needed while the pipeline is created. Specialised
  // here rather than by the driver: lavapipe creates it ~3x faster (Spirv.h).
  const std::vector<uint32_t> code = specialize_spirv(spirv, specialization);
  const bool specialized = code != spirv;
  VkShaderModuleCreateInfo smi{.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  smi.codeSize = code.size() * sizeof(uint32_t);
  smi.pCode = code.data();
  VkShaderModule sm = VK_NULL_HANDLE;
  VK_CHECK(vkCreateShaderModule(dev, &smi, nullptr, &sm));
  UniqueShaderModule module(sm, {dev});
  ctx.set_name(sm, name_.c_str());

  std::vector<VkSpecializationMapEntry> entries;
  std::vector<uint32_t> values;
  for (auto [id, value] : specialization) {
    entries.push_back({id, uint32_t(values.size() * sizeof(uint32_t)), sizeof(uint32_t)});
    values.push_back(value);
  }
  VkSpecializationInfo spec{uint32_t(entries.size()), entries.data(), values.size() * sizeof(uint32_t),
                            values.data()};

  VkComputePipelineCreateInfo ci{.sType = VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  ci.stage = {.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  ci.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  ci.stage.module = sm;
  ci.stage.pName = "main";
  ci.stage.pSpecializationInfo = (entries.empty() || specialized) ? nullptr : &spec;
  ci.layout = pl;
  VkPipeline p = VK_NULL_HANDLE;
  VK_CHECK(vkCreateComputePipelines(dev, VK_NULL_HANDLE, 1, &ci, nullptr, &p));
  pipeline_ = UniquePipeline(p, {dev});
  ctx.set_name(p, name_.c_str());
}

std::shared_ptr<const ComputePipeline> PipelineCache::get(
    const std::vector<uint32_t>& spirv, const std::vector<ComputePipeline::Binding>& bindings,
    uint32_t push_constant_bytes, const std::vector<std::pair<uint32_t, uint32_t>>& specialization,
    const char* debug_name) {
  std::vector<uint32_t> key{uint32_t(spirv.size()), push_constant_bytes, uint32_t(bindings.size()),
                            uint32_t(specialization.size())};
  for (const ComputePipeline::Binding& b : bindings) key.insert(key.end(), {b.binding, uint32_t(b.type), b.count});
  for (const auto& [id, value] : specialization) key.insert(key.end(), {id, value});
  for (const char* c = debug_name; c && *c; ++c) key.push_back(uint32_t(uint8_t(*c)));
  key.insert(key.end(), spirv.begin(), spirv.end());

  std::lock_guard lock(mutex_);
  for (auto it = entries_.begin(); it != entries_.end(); ++it)
    if (it->key == key) {
      entries_.splice(entries_.begin(), entries_, it);
      return entries_.front().pipeline;
    }
  auto made = std::make_shared<const ComputePipeline>(ctx_, spirv, bindings, push_constant_bytes, specialization,
                                                      debug_name);
  entries_.push_front({std::move(key), made});
  if (entries_.size() > kCapacity) entries_.pop_back();
  return made;
}

void ComputePipeline::bind(VkCommandBuffer cmd, VkDescriptorSet set) const {
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_.get());
  vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout_.get(), 0, 1, &set, 0, nullptr);
}

void ComputePipeline::push(VkCommandBuffer cmd, const void* data, uint32_t bytes) const {
  if (bytes > push_constant_bytes_)
    throw VulkanError("ComputePipeline " + name_ + ": push of " + std::to_string(bytes) + " bytes exceeds its " +
                      std::to_string(push_constant_bytes_) + "-byte push-constant block");
  vkCmdPushConstants(cmd, layout_.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, bytes, data);
}

ParameterBuffer::ParameterBuffer(Context& ctx, VkDeviceSize bytes, const char* name)
    : buffer_(ctx, bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
              MemoryKind::DeviceLocal, name) {}

void ParameterBuffer::record(VkCommandBuffer cmd, const void* data, VkDeviceSize bytes) const {
  // vkCmdUpdateBuffer's rules: 4-byte multiples, at most 64 KiB.
  if (bytes == 0 || bytes % 4 != 0 || bytes > buffer_.size() || bytes > 65536)
    throw VulkanError("ParameterBuffer: a write of " + std::to_string(bytes) + " bytes into " +
                      std::to_string(buffer_.size()));
  memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT,
                 VK_ACCESS_TRANSFER_WRITE_BIT);
  vkCmdUpdateBuffer(cmd, buffer_.buffer(), 0, bytes, data);
  memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT,
                 VK_ACCESS_SHADER_READ_BIT);
}

DescriptorSet::DescriptorSet(Context& ctx, const ComputePipeline& pipeline, const char* debug_name)
    : device_(ctx.device()), bindings_(pipeline.bindings()) {
  std::map<VkDescriptorType, uint32_t> counts;
  for (const auto& b : bindings_) counts[b.type] += b.count;
  std::vector<VkDescriptorPoolSize> sizes;
  for (auto [type, n] : counts) sizes.push_back({type, n});
  VkDescriptorPoolCreateInfo pci{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pci.maxSets = 1;
  pci.poolSizeCount = uint32_t(sizes.size());
  pci.pPoolSizes = sizes.data();
  VkDescriptorPool pool = VK_NULL_HANDLE;
  VK_CHECK(vkCreateDescriptorPool(device_, &pci, nullptr, &pool));
  pool_ = UniqueDescriptorPool(pool, {device_});
  std::string name = debug_name ? debug_name : pipeline.name() + " set";
  ctx.set_name(pool, name.c_str());

  VkDescriptorSetLayout sl = pipeline.set_layout();
  VkDescriptorSetAllocateInfo ai{.sType = VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  ai.descriptorPool = pool;
  ai.descriptorSetCount = 1;
  ai.pSetLayouts = &sl;
  VK_CHECK(vkAllocateDescriptorSets(device_, &ai, &set_));
  ctx.set_name(set_, name.c_str());
}

VkDescriptorType DescriptorSet::type_of(uint32_t binding) const {
  for (const auto& b : bindings_)
    if (b.binding == binding) return b.type;
  throw VulkanError("DescriptorSet: the pipeline has no binding " + std::to_string(binding));
}

// One descriptor of `binding`, array element `array_element`; exactly one of
// the three pointers is set, by the binding's type.
void DescriptorSet::write(uint32_t binding, uint32_t array_element, const VkDescriptorBufferInfo* buffer,
                          const VkDescriptorImageInfo* image, const VkBufferView* texel_buffer) {
  VkWriteDescriptorSet w{.sType = VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = set_;
  w.dstBinding = binding;
  w.dstArrayElement = array_element;
  w.descriptorCount = 1;
  w.descriptorType = type_of(binding);
  w.pBufferInfo = buffer;
  w.pImageInfo = image;
  w.pTexelBufferView = texel_buffer;
  vkUpdateDescriptorSets(device_, 1, &w, 0, nullptr);
}

void DescriptorSet::write_buffer(uint32_t binding, const Buffer& buffer, VkDeviceSize offset, VkDeviceSize range) {
  const VkDescriptorBufferInfo info{buffer.buffer(), offset, range};
  write(binding, 0, &info, nullptr, nullptr);
}

void DescriptorSet::write_texel_buffer(uint32_t binding, VkBufferView view, uint32_t array_element) {
  write(binding, array_element, nullptr, nullptr, &view);
}

void DescriptorSet::write_image(uint32_t binding, VkImageView view, VkSampler sampler, VkImageLayout layout,
                                uint32_t array_element) {
  const VkDescriptorImageInfo info{sampler, view, layout};
  write(binding, array_element, nullptr, &info, nullptr);
}

}  // namespace pyrolume::vk
