#include "render/vulkan/RenderSession.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "geometry/SceneSurfaces.h"
#include "light/EmissionCdf.h"
#include "light/EnvironmentMap.h"
#include "render/Limits.h"
#include "render/SceneChecks.h"
#include "render/vulkan/LightPacking.h"
#include "render/vulkan/RenderSessionParts.h"
#include "render/vulkan/Spirv.h"
#include "render/vulkan/SurfacePacking.h"
#include "scene/MediumVolume.h"
#include "util/Error.h"

namespace pyrolume {

using namespace session;

RenderSession::RenderSession(vk::Context& ctx, const Scene& scene, const RenderSettings& settings,
                             const VulkanHooks& hooks)
    : ctx_(ctx), settings_(settings), hooks_(hooks) {
  check_sizes(scene);
  check_scene_ranges(scene);
  // Load only what the scene uses: the grids of its vdb media, each checked
  // against the device's texture limits before its dense array is allocated.
  volumes_.resize(scene.media.size());
  for (size_t i = 0; i < scene.media.size(); ++i) {
    if (scene.media[i].type != Medium::Type::Vdb) continue;
    volumes_[i] = load_stored_volume(scene.media[i], dense_limits());
    for (const auto& w : volumes_[i]->warnings) warnings_.push_back(w);
  }
  check_loaded_media(scene, volumes_);
  gpu_scene_ = build_gpu_scene(scene, volumes_, /*with_luts=*/true, shared_texture_bytes());

  // Storage buffers, not uniform ones: lavapipe would inline their values
  // where they decide a branch and compile a shader variant for every pass
  // (shaders/render_bindings.glsl).
  frame_buffer_ = vk::Buffer(ctx, sizeof(gpu::FrameConstants), kStorage, vk::MemoryKind::HostVisible, "frame constants");
  media_buffer_ = vk::Buffer(ctx, gpu::MAX_MEDIA * sizeof(gpu::GpuMedium), kStorage, vk::MemoryKind::HostVisible, "media");
  grid_buffer_ = vk::Buffer(ctx, gpu::MAX_GRIDS * sizeof(gpu::GpuGrid), kUniform, vk::MemoryKind::HostVisible, "grids");
  create_majorant_buffer(scene);
  create_accumulation();
  create_textures(scene);
  create_surfaces(scene);
  create_environment(scene);
  emission_headers_ = vk::Buffer(ctx, gpu::MAX_GRIDS * sizeof(gpu::GpuEmissionCdf), kStorage,
                                 vk::MemoryKind::HostVisible, "emission light headers");
  upload_emission_lights(build_emission_lights(scene, volumes_, gpu_scene_));

  spec_ = spec_constants(scene, gpu_scene_, settings, light_selection_);
  const std::vector<uint32_t> code = vk::load_spirv("render.comp");
  create_pipeline(code);
  create_wavefront(code);
  write_descriptors();
  upload_constants(scene);
  warm_up();
}

void RenderSession::check_sizes(const Scene& scene) const {
  // The accumulation buffer is one storage buffer: check it fits the device
  // (lavapipe allows 128 MiB, about 1448² pixels) and its host readback
  // (texels plus double sums) fits the machine, before loading anything.
  const VkDeviceSize range = ctx_.properties().limits.maxStorageBufferRange;
  const bool range_binds = range <= ctx_.max_allocation_size();
  check_accumulation_size(scene.file.string(), settings_.width, settings_.height, sizeof(gpu::AccumTexel),
                          range_binds ? range : ctx_.max_allocation_size(),
                          range_binds ? "this device's maxStorageBufferRange" : "this device's maxMemoryAllocationSize");
  // The alpha texels follow the AccumTexels in the same buffer, as a binding of their own.
  // So do the AOV texels (settings_.aovs), with the AOV sums' doubles on the host.
  const size_t aov_bytes = settings_.aovs ? sizeof(gpu::AovLightTexel) + sizeof(gpu::AovFeatureTexel) : 0;
  const size_t aov_host_bytes = settings_.aovs ? kAovValues * sizeof(double) : 0;
  check_accumulation_size(scene.file.string(), settings_.width, settings_.height,
                          sizeof(gpu::AccumTexel) + sizeof(gpu::AlphaTexel) + aov_bytes, ctx_.max_allocation_size(),
                          "this device's maxMemoryAllocationSize");
  // With the AOVs, the guide's points too: about two vec4s a pixel (guide_points_).
  const size_t guide_bytes = settings_.aovs ? 8 * sizeof(float) : 0;
  check_accumulation_fits_memory(scene.file.string(), settings_.width, settings_.height,
                                 sizeof(gpu::AccumTexel) + sizeof(gpu::AlphaTexel) + aov_bytes + guide_bytes +
                                     8 * sizeof(double) + aov_host_bytes);
}

// The accumulation buffer: AccumTexels, then AlphaTexels and (settings.aovs)
// the AOV texels, each at an offset its binding may start at; its copy for
// undoing a pass, and the pass's constants and status.
void RenderSession::create_accumulation() {
  const VkDeviceSize pixels = VkDeviceSize(settings_.width) * VkDeviceSize(settings_.height);
  const VkDeviceSize align = std::max<VkDeviceSize>(ctx_.properties().limits.minStorageBufferOffsetAlignment, 1);
  auto aligned = [&](VkDeviceSize bytes) { return (bytes + align - 1) / align * align; };
  alpha_offset_ = aligned(pixels * sizeof(gpu::AccumTexel));
  VkDeviceSize accum_bytes = alpha_offset_ + pixels * sizeof(gpu::AlphaTexel);
  if (settings_.aovs) {
    aov_lights_offset_ = aligned(accum_bytes);
    aov_features_offset_ = aligned(aov_lights_offset_ + pixels * sizeof(gpu::AovLightTexel));
    accum_bytes = aov_features_offset_ + pixels * sizeof(gpu::AovFeatureTexel);
  }
  accum_ = vk::Buffer(ctx_, accum_bytes,
                      VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
                          VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                      vk::MemoryKind::DeviceLocal, "accumulation");
  accum_backup_ = vk::Buffer(ctx_, accum_.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                             vk::MemoryKind::DeviceLocal, "accumulation before the pass");
  const VkDeviceSize guide_points =
      settings_.aovs ? (VkDeviceSize(settings_.width) + 1) * (VkDeviceSize(settings_.height) + 1) + pixels : 1;
  guide_points_ = vk::Buffer(ctx_, guide_points * 4 * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                             vk::MemoryKind::DeviceLocal, "guide points");
  pass_constants_ = vk::ParameterBuffer(ctx_, sizeof(gpu::PassConstants), "pass constants");
  pass_status_ = vk::Buffer(ctx_, sizeof(gpu::PassStatus), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                            vk::MemoryKind::HostVisible, "pass status");
}

void RenderSession::create_pipeline(const std::vector<uint32_t>& code) {
  const std::vector<vk::ComputePipeline::Binding> bindings{
      {gpu::BINDING_FRAME, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_MEDIA, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_ACCUM, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_ALPHA, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_AOV_LIGHTS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_AOV_FEATURES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_GRIDS, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER},
      {gpu::BINDING_MAJORANTS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER},
      {gpu::BINDING_DENSITY, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, gpu::MAX_GRIDS},
      {gpu::BINDING_TEMPERATURE, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, gpu::MAX_GRIDS},
      {gpu::BINDING_BLACKBODY, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, gpu::MAX_GRIDS},
      {gpu::BINDING_DENSITY_TEXELS, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER, gpu::MAX_GRIDS},
      {gpu::BINDING_BVH_NODES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_BVH_TRIANGLES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_BVH_ATTRIBUTES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_SURFACE_SHAPES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_MATERIALS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_TEXTURES, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, gpu::MAX_TEXTURES},
      {gpu::BINDING_ENV_TEXELS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_ENV_CDF, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_ENV_HEADER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_EMISSION_CDF, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_EMISSION_CELLS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_EMISSION_PMF, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_EMISSION_CLUSTERS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_EMISSION_HEADERS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_LIGHTS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_PASS_STATUS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_PATHS, VK_DESCRIPTOR_TYPE_STORAGE_TEXEL_BUFFER},
      {gpu::BINDING_SPARSE, VK_DESCRIPTOR_TYPE_UNIFORM_TEXEL_BUFFER},
      {gpu::BINDING_QUEUES, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_PASS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER},
      {gpu::BINDING_GUIDE_POINTS, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}};
  pipeline_ = ctx_.pipelines().get(code, bindings, /*push_constant_bytes=*/0, spec_, "render");
  // film.aovs: the guide's marches, a pipeline of their own (shaders/guide.comp).
  if (settings_.aovs)
    guide_pipeline_ = ctx_.pipelines().get(vk::load_spirv("guide.comp"), bindings, /*push_constant_bytes=*/0, spec_,
                                           "guide");
  set_.emplace(ctx_, *pipeline_, "render set");
}

void RenderSession::write_descriptors() {
  const VkDeviceSize pixels = VkDeviceSize(settings_.width) * VkDeviceSize(settings_.height);
  set_->write_buffer(gpu::BINDING_FRAME, frame_buffer_);
  set_->write_buffer(gpu::BINDING_MEDIA, media_buffer_);
  set_->write_buffer(gpu::BINDING_ACCUM, accum_, 0, accumulation_texel_bytes());
  const VkDeviceSize alpha_bytes = pixels * sizeof(gpu::AlphaTexel);
  set_->write_buffer(gpu::BINDING_ALPHA, accum_, alpha_offset_, alpha_bytes);
  if (settings_.aovs) {
    set_->write_buffer(gpu::BINDING_AOV_LIGHTS, accum_, aov_lights_offset_, pixels * sizeof(gpu::AovLightTexel));
    set_->write_buffer(gpu::BINDING_AOV_FEATURES, accum_, aov_features_offset_, pixels * sizeof(gpu::AovFeatureTexel));
  } else {  // compiled out (AOVS false), but every binding needs a buffer
    set_->write_buffer(gpu::BINDING_AOV_LIGHTS, accum_, alpha_offset_, alpha_bytes);
    set_->write_buffer(gpu::BINDING_AOV_FEATURES, accum_, alpha_offset_, alpha_bytes);
  }
  set_->write_buffer(gpu::BINDING_PASS_STATUS, pass_status_);
  set_->write_buffer(gpu::BINDING_PASS, pass_constants_.buffer());
  set_->write_buffer(gpu::BINDING_GUIDE_POINTS, guide_points_);
  set_->write_buffer(gpu::BINDING_GRIDS, grid_buffer_);
  write_grid_descriptors();
  set_->write_buffer(gpu::BINDING_BVH_NODES, bvh_nodes_);
  set_->write_buffer(gpu::BINDING_BVH_TRIANGLES, bvh_triangles_);
  set_->write_buffer(gpu::BINDING_BVH_ATTRIBUTES, bvh_attributes_);
  set_->write_buffer(gpu::BINDING_SURFACE_SHAPES, surface_shapes_);
  set_->write_buffer(gpu::BINDING_MATERIALS, materials_);
  set_->write_buffer(gpu::BINDING_ENV_TEXELS, env_texels_);
  set_->write_buffer(gpu::BINDING_ENV_CDF, env_cdf_);
  set_->write_buffer(gpu::BINDING_ENV_HEADER, env_header_);
  for (uint32_t slot = 0; slot < gpu::MAX_TEXTURES; ++slot)
    set_->write_image(gpu::BINDING_TEXTURES, textures_2d_[slot + 1 < textures_2d_.size() ? slot + 1 : 0], slot);
}

void RenderSession::warm_up() {
  // A driver may compile a pipeline inside its first dispatch (~0.1–0.5 s;
  // lavapipe did while it inlined uniforms, docs/rendering.md): dispatch one
  // empty workgroup now so that cost counts as loading, not rendering
  // (docs/benchmarks.md: `seconds` starts at the first real pass).
  ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
    pass_constants_.record(cmd, gpu::PassConstants{0u, 0u, 0u, 0u});
    if (guide_pipeline_) {  // (rows 0..0 of corners: it marches nothing)
      guide_pipeline_->bind(cmd, set_->set());
      vkCmdDispatch(cmd, 1, 1, 1);
      vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
    }
    pipeline_->bind(cmd, set_->set());
    vkCmdDispatch(cmd, 1, 1, 1);
    // The wavefront's stages, on empty queues (the queues are zero).
    for (const auto& stage : wavefront_stages_) {
      stage->bind(cmd, set_->set());
      vkCmdDispatch(cmd, 1, 1, 1);
    }
  });
}

// The shader variant: code for grids, scattering and emission only when used.
std::vector<std::pair<uint32_t, uint32_t>> RenderSession::spec_constants(const Scene& scene, const GpuScene& g,
                                                                        const RenderSettings& settings,
                                                                        const LightSelection& lights) const {
  auto flag = [](bool b) { return uint32_t(b ? 1 : 0); };
  return {{gpu::SPEC_HAS_GRIDS, flag(g.has_grids)},
          {gpu::SPEC_HAS_ANALYTIC_MEDIA, flag(g.has_analytic)},
          {gpu::SPEC_ALBEDO_TEXTURE_COUNT,
           uint32_t(std::min<size_t>(textures_2d_.empty() ? 0 : textures_2d_.size() - 1, gpu::MAX_TEXTURES))},
          {gpu::SPEC_HAS_SCATTERING, flag(g.has_scattering && scene.integrator.max_depth > 0)},
          {gpu::SPEC_HAS_EMISSION, flag(g.has_emission)},
          {gpu::SPEC_TEMPERATURE_IN_DENSITY, flag(g.temperature_in_density)},
          {gpu::SPEC_SPARSE_GRIDS, flag(g.has_sparse())},
          {gpu::SPEC_STOCHASTIC_DENSITY, flag(stochastic_density(g))},
          {gpu::SPEC_COLLISION_ESTIMATOR, flag(lights.estimator != EmissionEstimator::Absorption)},
          {gpu::SPEC_DEBUG_MODE, hooks_.debug_mode},
          {gpu::SPEC_MEDIUM_COUNT, uint32_t(g.media.size())},
          {gpu::SPEC_GRID_COUNT, uint32_t(g.grids.size())},
          {gpu::SPEC_HAS_SURFACES, flag(!scene.shapes.empty())},
          {gpu::SPEC_SURFACE_SHAPE_COUNT, gpu_surfaces_.shape_count},
          {gpu::SPEC_SURFACE_HAS_TRIANGLES, flag(gpu_surfaces_.triangle_count > 0)},
          {gpu::SPEC_HAS_ENVIRONMENT, flag(scene.environment.has_value())},
          {gpu::SPEC_LIGHT_COUNT, uint32_t(scene.lights.size())},
          {gpu::SPEC_AOVS, flag(settings.aovs)},
          {gpu::SPEC_LIGHT_STRATEGY, lights.strategy == LightStrategy::Mis         ? gpu::LIGHT_STRATEGY_MIS
                                     : lights.strategy == LightStrategy::LightOnly ? gpu::LIGHT_STRATEGY_LIGHT_ONLY
                                                                                   : gpu::LIGHT_STRATEGY_BSDF},
          {gpu::SPEC_GUIDED_CONTINUATION, flag(lights.p_continue_own < 1.0)},
          // Leaving the free-flight loop early pays where flights are long
          // and an event's code is short: media alone with BSDF/phase
          // sampling, 1.04–1.28×. With next-event estimation (0.8–0.95×) or
          // surfaces (0.96–0.98×) the extra pass through the event code
          // costs more than the wait (docs/benchmarks.md "Lanes in the
          // free-flight loop").
          {gpu::SPEC_EARLY_EVENT_EXIT,
           flag(hooks_.early_event_exit && lights.strategy == LightStrategy::Bsdf && scene.shapes.empty() &&
                ctx_.features().subgroup_ballot)}};
}

// The bindings that change with the media's grids.
void RenderSession::write_grid_descriptors() {
  set_->write_texel_buffer(gpu::BINDING_MAJORANTS, majorant_view_.get());
  set_->write_buffer(gpu::BINDING_EMISSION_CDF, emission_cdf_);
  set_->write_buffer(gpu::BINDING_EMISSION_CELLS, emission_cells_);
  set_->write_buffer(gpu::BINDING_EMISSION_PMF, emission_pmf_);
  set_->write_buffer(gpu::BINDING_EMISSION_CLUSTERS, emission_clusters_);
  set_->write_buffer(gpu::BINDING_EMISSION_HEADERS, emission_headers_);
  set_->write_buffer(gpu::BINDING_LIGHTS, analytic_lights_);
  // textures_3d_[0] / textures_1d_[0] are 1-texel placeholders for unused slots.
  for (uint32_t slot = 0; slot < gpu::MAX_GRIDS; ++slot) {
    const bool used = slot < gpu_scene_.grid_sources.size();
    const size_t d = used ? 1 + 2 * slot : 0, t = used ? 2 + 2 * slot : 0, b = used ? 1 + slot : 0;
    set_->write_image(gpu::BINDING_DENSITY, textures_3d_[d], slot);
    set_->write_image(gpu::BINDING_TEMPERATURE, textures_3d_[t], slot);
    set_->write_image(gpu::BINDING_BLACKBODY, textures_1d_[b], slot);
    const size_t texels = 1 + slot < density_texel_views_.size() ? 1 + slot : 0;
    set_->write_texel_buffer(gpu::BINDING_DENSITY_TEXELS, density_texel_views_[texels].get(), slot);
  }
  if (sparse_view_) {
    set_->write_texel_buffer(gpu::BINDING_SPARSE, sparse_view_.get());
  }
}

void RenderSession::update(const Scene& scene) { upload_constants(scene); }

void RenderSession::reset() {
  spp_done_ = 0;
  needs_clear_ = true;
}

}  // namespace pyrolume
