#include "render/vulkan/VulkanRenderer.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "render/vulkan/Context.h"
#include "render/vulkan/GpuScene.h"
#include "render/vulkan/Memory.h"
#include "render/vulkan/Pipeline.h"
#include "render/vulkan/Spirv.h"
#include "scene/Scene.h"

namespace pyrolume {
namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

VulkanRenderer::VulkanRenderer(const BackendOptions& options) {
  auto t0 = Clock::now();
  vk::Context::Options o;
  o.device_index = options.device_index;
  o.validation = options.validation;
  context_ = std::make_unique<vk::Context>(o);
  context_seconds_ = since(t0);
}

VulkanRenderer::~VulkanRenderer() = default;

std::string VulkanRenderer::device_name() const { return context_->info().name; }

uint64_t VulkanRenderer::validation_messages() const { return context_->validation_messages(); }

int VulkanRenderer::spp_per_pass(int width, int height, int spp) {
  // About 2^19 paths per dispatch: tens of milliseconds on lavapipe for simple
  // scenes, far below any GPU watchdog, and large enough that per-dispatch
  // overhead (~1.3 ms on lavapipe, LAVAPIPE.md) stays small.
  const double paths_per_pass = 524288.0;
  int k = static_cast<int>(paths_per_pass / (double(width) * double(height)));
  return std::clamp(k, 1, std::min(spp, 64));
}

RenderResult VulkanRenderer::render(const Scene& scene, const RenderSettings& settings, const RenderControl& control) {
  auto load_start = Clock::now();
  vk::Context& ctx = *context_;
  const uint32_t width = uint32_t(settings.width), height = uint32_t(settings.height);
  const size_t pixels = size_t(width) * height;

  std::vector<gpu::GpuMedium> media = build_gpu_media(scene);
  gpu::FrameConstants frame = build_frame_constants(scene, settings, uint32_t(media.size()));
  if (media.empty()) media.push_back(gpu::GpuMedium{});  // a buffer may not be empty

  vk::Buffer frame_buffer(ctx, sizeof frame, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, vk::MemoryKind::HostVisible,
                          "frame constants");
  frame_buffer.upload(ctx, &frame, sizeof frame);
  vk::Buffer media_buffer(ctx, media.size() * sizeof(gpu::GpuMedium), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                          vk::MemoryKind::HostVisible, "media");
  media_buffer.upload(ctx, media.data(), media.size() * sizeof(gpu::GpuMedium));
  const VkDeviceSize accum_bytes = pixels * sizeof(gpu::AccumTexel);
  vk::Buffer accum(ctx, accum_bytes,
                   VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                       VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                   vk::MemoryKind::DeviceLocal, "accumulation");

  vk::ComputePipeline pipeline(ctx, vk::load_spirv("render.comp"),
                               {{gpu::BINDING_FRAME, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
                                {gpu::BINDING_MEDIA, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                                {gpu::BINDING_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}},
                               sizeof(gpu::PassConstants), {}, "render");
  vk::DescriptorSet set(ctx, pipeline, "render set");
  set.write_buffer(gpu::BINDING_FRAME, frame_buffer);
  set.write_buffer(gpu::BINDING_MEDIA, media_buffer);
  set.write_buffer(gpu::BINDING_ACCUM, accum);

  RenderResult result;
  result.width = settings.width;
  result.height = settings.height;
  result.backend = name();
  result.device = device_name();
  result.load_seconds = since(load_start) + context_seconds_;
  context_seconds_ = 0.0;

  // Progressive passes.
  auto render_start = Clock::now();
  const int per_pass = spp_per_pass(settings.width, settings.height, settings.spp);
  const uint32_t groups_x = (width + gpu::WORKGROUP_SIZE_X - 1) / gpu::WORKGROUP_SIZE_X;
  const uint32_t groups_y = (height + gpu::WORKGROUP_SIZE_Y - 1) / gpu::WORKGROUP_SIZE_Y;
  int done = 0;
  while (done < settings.spp) {
    gpu::PassConstants pass{uint32_t(done), uint32_t(std::min(per_pass, settings.spp - done)), 0u, 0u};
    const bool first = done == 0;
    ctx.submit_and_wait([&](VkCommandBuffer cmd) {
      if (first) {
        vkCmdFillBuffer(cmd, accum.buffer(), 0, VK_WHOLE_SIZE, 0u);
        vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                           VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
      }
      pipeline.bind(cmd, set.set());
      pipeline.push(cmd, pass);
      vkCmdDispatch(cmd, groups_x, groups_y, 1);
      vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT);
    });
    done += int(pass.spp);
    if (control.progress) control.progress(done, settings.spp);
    if (control.cancel && control.cancel->load()) {
      result.cancelled = true;
      break;
    }
    if (settings.time_limit > 0 && since(render_start) >= settings.time_limit) break;
  }

  std::vector<gpu::AccumTexel> texels(pixels);
  if (done > 0) accum.download(ctx, texels.data(), accum_bytes);
  result.spp = done;
  result.sum.resize(pixels * 3);
  result.sum_sq.resize(pixels * 3);
  for (size_t i = 0; i < pixels; ++i) {
    const gpu::AccumTexel& t = texels[i];
    for (int c = 0; c < 3; ++c) {
      // Kahan: the running sum minus its pending compensation.
      result.sum[i * 3 + c] = double(t.sum[c]) - double(t.sum_c[c]);
      result.sum_sq[i * 3 + c] = double(t.sum_sq[c]) - double(t.sum_sq_c[c]);
    }
    result.events += double(t.sum.w) - double(t.sum_c.w);
    result.density_lookups += double(t.sum_sq.w);
    result.nonfinite_samples += uint64_t(t.sum_sq_c.w);
  }
  result.seconds = since(render_start);
  return result;
}

}  // namespace pyrolume
