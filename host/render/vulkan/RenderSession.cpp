#include "render/vulkan/RenderSession.h"

#include "render/vulkan/GpuScene.h"
#include "render/vulkan/Spirv.h"

namespace pyrolume {
namespace {
constexpr size_t kMediaCapacity = gpu::MAX_MEDIA;

vk::ComputePipeline make_pipeline(vk::Context& ctx) {
  return vk::ComputePipeline(ctx, vk::load_spirv("render.comp"),
                             {{gpu::BINDING_FRAME, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
                              {gpu::BINDING_MEDIA, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
                              {gpu::BINDING_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}},
                             sizeof(gpu::PassConstants), {}, "render");
}
}  // namespace

RenderSession::RenderSession(vk::Context& ctx, const Scene& scene, const RenderSettings& settings)
    : ctx_(ctx),
      settings_(settings),
      frame_buffer_(ctx, sizeof(gpu::FrameConstants), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, vk::MemoryKind::HostVisible,
                    "frame constants"),
      media_buffer_(ctx, kMediaCapacity * sizeof(gpu::GpuMedium), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                    vk::MemoryKind::HostVisible, "media"),
      accum_(ctx, size_t(settings.width) * size_t(settings.height) * sizeof(gpu::AccumTexel),
             VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
             vk::MemoryKind::DeviceLocal, "accumulation"),
      pipeline_(make_pipeline(ctx)),
      set_(ctx, pipeline_, "render set") {
  set_.write_buffer(gpu::BINDING_FRAME, frame_buffer_);
  set_.write_buffer(gpu::BINDING_MEDIA, media_buffer_);
  set_.write_buffer(gpu::BINDING_ACCUM, accum_);
  upload_scene(scene);
}

void RenderSession::upload_scene(const Scene& scene) {
  std::vector<gpu::GpuMedium> media = build_gpu_media(scene);
  gpu::FrameConstants frame = build_frame_constants(scene, settings_, uint32_t(media.size()));
  frame_buffer_.upload(ctx_, &frame, sizeof frame);
  if (!media.empty()) media_buffer_.upload(ctx_, media.data(), media.size() * sizeof(gpu::GpuMedium));
  reset();
}

void RenderSession::update(const Scene& scene) { upload_scene(scene); }

void RenderSession::reset() {
  spp_done_ = 0;
  needs_clear_ = true;
}

void RenderSession::record_pass(VkCommandBuffer cmd, int spp) {
  if (needs_clear_) {
    vkCmdFillBuffer(cmd, accum_.buffer(), 0, VK_WHOLE_SIZE, 0u);
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    needs_clear_ = false;
  }
  gpu::PassConstants pass{uint32_t(spp_done_), uint32_t(spp), 0u, 0u};
  pipeline_.bind(cmd, set_.set());
  pipeline_.push(cmd, pass);
  const uint32_t groups_x = (uint32_t(settings_.width) + gpu::WORKGROUP_SIZE_X - 1) / gpu::WORKGROUP_SIZE_X;
  const uint32_t groups_y = (uint32_t(settings_.height) + gpu::WORKGROUP_SIZE_Y - 1) / gpu::WORKGROUP_SIZE_Y;
  vkCmdDispatch(cmd, groups_x, groups_y, 1);
  // The next pass, a readback copy or a display shader reads what this one wrote.
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT);
  spp_done_ += spp;
}

void RenderSession::run_pass(int spp) {
  ctx_.submit_and_wait([&](VkCommandBuffer cmd) { record_pass(cmd, spp); });
}

void RenderSession::read(RenderResult& result) {
  const size_t pixels = size_t(settings_.width) * size_t(settings_.height);
  std::vector<gpu::AccumTexel> texels(pixels);
  if (spp_done_ > 0 && !needs_clear_) accum_.download(ctx_, texels.data(), pixels * sizeof(gpu::AccumTexel));
  result.width = settings_.width;
  result.height = settings_.height;
  result.spp = spp_done_;
  result.sum.assign(pixels * 3, 0.0);
  result.sum_sq.assign(pixels * 3, 0.0);
  result.events = result.density_lookups = 0.0;
  result.nonfinite_samples = 0;
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
}

}  // namespace pyrolume
