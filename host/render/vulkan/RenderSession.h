#pragma once
// One scene on one device, ready to accumulate samples: the uploaded constants,
// media, grid textures, majorant cells and blackbody LUTs, the pipeline
// specialised to the scene, and the per-pixel accumulation buffer. `render` and
// the preview window both drive it, pass by pass.
#include <atomic>
#include <memory>
#include <optional>
#include <vector>

#include "render/Render.h"
#include "render/vulkan/Context.h"
#include "render/vulkan/GpuScene.h"
#include "render/vulkan/LightPacking.h"
#include "render/vulkan/Memory.h"
#include "render/vulkan/Pipeline.h"
#include "render/vulkan/SurfacePacking.h"
#include "render/vulkan/VulkanHooks.h"
#include "scene/Scene.h"
#include "shared/gpu_types.h"
#include "shared/light_types.h"
#include "light/EnvironmentMap.h"
#include "light/LightSelection.h"
#include "volume/StoredVolume.h"

namespace pyrolume {

class RenderSession {
 public:
  RenderSession(vk::Context& ctx, const Scene& scene, const RenderSettings& settings, const VulkanHooks& hooks = {});

  // The next frame of a sequence (docs/animation.md): reload the media's grids
  // and re-upload only what depends on them (3D textures, majorant cells,
  // blackbody LUTs, constants), keeping the pipeline, the surfaces' BVH and
  // textures, the environment map and the accumulation buffer. Returns false,
  // changing nothing, when the frame needs a different session (another image
  // size, debug mode, medium count or shader variant); the caller then builds
  // a new one. Assumes the shapes and the environment are the ones this
  // session was built with (a sequence changes only media and keyed values).
  bool load_frame(const Scene& scene, const RenderSettings& settings);

  // Re-upload what the scene changes (camera, media parameters, temperature
  // mapping, density scale) and restart the accumulation. Image size, grids,
  // textures and the shader variant stay as constructed.
  void update(const Scene& scene);
  // Zero the accumulation; the next pass starts at sample 0 again.
  void reset();
  // Record one pass of `spp` samples per pixel into cmd (the caller submits).
  // Passes must be submitted in the order they were recorded.
  void record_pass(VkCommandBuffer cmd, int spp);
  // Record, submit and wait, in bands of rows, each dispatch sized to finish
  // well under a second (band_rows()). `cancel` (SIGINT/SIGTERM) is checked
  // between bands: a pass it interrupts is undone (the accumulation restored
  // from the copy taken before it) and false is returned. If a submission
  // fails (VulkanError), spp_done() stays as it was: the accumulation holds
  // the passes before this one.
  bool run_pass(int spp, const std::atomic<bool>* cancel = nullptr);
  // The seconds the guide's dispatches took (settings.aovs), summed over the
  // passes run so far.
  double guide_seconds() const { return guide_seconds_; }
  // The rows one dispatch covers now: starts small, grows while dispatches
  // take under kBandFastSeconds and shrinks when one takes over kBandSlowSeconds.
  int band_rows() const { return band_rows_; }
  static constexpr double kBandFastSeconds = 0.05, kBandSlowSeconds = 0.25;

  int spp_done() const { return spp_done_; }
  // Passes are split when the device cannot finish them (PassStatus): the
  // largest pass size that has worked, and the samples lost at 1 spp per pass.
  int max_pass_spp() const { return max_pass_spp_; }
  // Next-event estimation is on: every vertex sends a light ray too.
  bool next_event_estimation() const { return light_selection_.strategy != LightStrategy::Bsdf; }
  const LightSelection& light_selection() const { return light_selection_; }
  const GpuScene& gpu_scene() const { return gpu_scene_; }
  // Rays a vertex may send: its continuation, and with next-event estimation
  // up to surface_light_samples light rays and the ratio-tracked
  // continuation's ray (VulkanRenderer::spp_per_pass).
  int rays_per_vertex() const {
    return next_event_estimation()
               ? 1 + light_selection_.surface_light_samples + (light_selection_.ratio_tracked_continuation ? 1 : 0)
               : 1;
  }
  uint64_t dropped_samples() const { return dropped_samples_; }
  int width() const { return settings_.width; }
  int height() const { return settings_.height; }
  // AccumTexel per pixel (shaders/shared/gpu_types.h), row 0 = top.
  const vk::Buffer& accumulation() const { return accum_; }
  // The AccumTexels' part of accumulation() (the AlphaTexels follow).
  VkDeviceSize accumulation_texel_bytes() const {
    return VkDeviceSize(settings_.width) * VkDeviceSize(settings_.height) * sizeof(gpu::AccumTexel);
  }
  // Read the sums and counters back into result (sum, sum_sq, spp, counters).
  void read(RenderResult& result);
  // The accumulation as it is on the device (raw AccumTexels, backend "vulkan"),
  // for checkpoints; and back: the next pass continues at state.spp with the
  // same Kahan sums and compensations, so it equals an uninterrupted render.
  AccumulationState save_state();
  void load_state(const AccumulationState& state);
  // settings.aovs: the AOV sums into result.aov_sum (not part of the saved
  // state: checkpoints do not carry AOVs). Empty without AOVs.
  void read_aovs(RenderResult& result);
  // A saved state's sums and counters, as read() would give them.
  static void result_from_state(const AccumulationState& state, RenderResult& result);
  // Warnings from loading the grids (one line each).
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  // Set-up (RenderSession.cpp), in the constructor's order: the accumulation's
  // size against the device and the machine; the accumulation buffers; the
  // pipeline with every binding; the descriptors; one empty dispatch.
  void check_sizes(const Scene& scene) const;
  void create_accumulation();
  void create_pipeline(const std::vector<uint32_t>& code);
  void write_descriptors();
  void warm_up();
  DenseLimits dense_limits() const;  // this device's 3D texture limits, for the grid loader
  uint64_t shared_texture_bytes() const;
  void upload_constants(const Scene& scene);
  void create_textures(const Scene& scene);
  void create_sparse_buffer(const Scene& scene);
  void create_majorant_buffer(const Scene& scene);
  // Whether free flights read the density stochastically: every grid is a
  // dense texture whose texels also fit a texel buffer.
  bool stochastic_density(const GpuScene& g) const;
  void create_density_texels();
  void create_surfaces(const Scene& scene);
  void create_environment(const Scene& scene);
  // The emission CDFs of the emissive grids and the light selection for
  // next-event estimation (docs/mis.md), from the loaded volumes.
  struct EmissionLights {
    LightSelection selection;
    GpuEmissionLights emission;
    std::vector<gpu::GpuLight> analytic;  // the scene's `lights` (one placeholder when none)
  };
  EmissionLights build_emission_lights(const Scene& scene, const std::vector<std::optional<StoredVolume>>& volumes,
                                       const GpuScene& gpu_scene) const;
  void upload_emission_lights(const EmissionLights& lights);
  std::vector<std::pair<uint32_t, uint32_t>> spec_constants(const Scene& scene, const GpuScene& gpu_scene,
                                                           const RenderSettings& settings,
                                                           const LightSelection& lights) const;
  void write_grid_descriptors();

  vk::Context& ctx_;
  RenderSettings settings_;
  VulkanHooks hooks_;  // fixed for the session (VulkanRenderer::set_hooks drops a kept one)
  std::vector<std::optional<StoredVolume>> volumes_;
  std::vector<std::string> warnings_;
  GpuScene gpu_scene_;
  vk::Buffer frame_buffer_, media_buffer_, grid_buffer_, accum_;
  // Every grid's majorant cells and line rates (GpuScene::majorants), read as
  // a uniform texel buffer of r32f (shaders/render_bindings.glsl).
  vk::Buffer majorant_buffer_;
  vk::UniqueBufferView majorant_view_;
  std::vector<vk::Image3D> textures_3d_;
  std::vector<vk::Image1D> textures_1d_;
  // Each grid slot's density texels for stochastic lookups (a one-texel
  // placeholder where unused; shaders/media.glsl stochastic_density).
  std::vector<vk::Buffer> density_texels_;
  std::vector<vk::UniqueBufferView> density_texel_views_;
  // Surfaces: BVH nodes, triangles, triangle attributes, shapes, materials.
  geometry::GpuSurfaces gpu_surfaces_;
  vk::Buffer bvh_nodes_, bvh_triangles_, bvh_attributes_, surface_shapes_, materials_;
  std::vector<vk::Image2D> textures_2d_;  // [0] placeholder, then one per albedo texture
  // The environment map: texels, sampling CDF, header.
  vk::Buffer env_texels_, env_cdf_, env_header_;
  std::optional<EnvironmentMap> environment_;
  // The emissive grids as lights: CDF entries, their cells, per-cell pmf, headers.
  vk::Buffer emission_cdf_, emission_cells_, emission_pmf_, emission_clusters_, emission_headers_;
  vk::Buffer analytic_lights_;
  LightSelection light_selection_;
  std::shared_ptr<const vk::ComputePipeline> pipeline_;  // from ctx_.pipelines()
  std::optional<vk::DescriptorSet> set_;
  std::vector<std::pair<uint32_t, uint32_t>> spec_;  // the variant pipeline_ was compiled for
  vk::ParameterBuffer pass_constants_;  // PassConstants of the dispatch recorded last (record_band)
  vk::Buffer pass_status_, accum_backup_;  // PassStatus; the accumulation before the pass in flight
  VkDeviceSize alpha_offset_ = 0;          // where accum_'s AlphaTexels start (aligned for their binding)
  // settings.aovs: where accum_'s AovLightTexels and AovFeatureTexels start
  // (0: no AOVs, their bindings then show the AlphaTexels, unread).
  VkDeviceSize aov_lights_offset_ = 0, aov_features_offset_ = 0;
  // settings.aovs: the denoiser's guide at the pixels' corners ((width + 1) ×
  // (height + 1) vec4s), then at their centres, marched before the first pass
  // (march_guide_points), which reads them (accumulation.glsl
  // add_pixel_guide). Without AOVs a buffer of one vec4, unread.
  vk::Buffer guide_points_;
  double guide_seconds_ = 0.0;  // march_guide_points' wall time, summed over this session's renders
  std::shared_ptr<const vk::ComputePipeline> guide_pipeline_;  // settings.aovs: shaders/guide.comp
  bool march_guide_points(const std::atomic<bool>* cancel);
  static constexpr uint32_t kGuideBandCorners = 1u << 16;  // pixel corners per guide dispatch
  int max_pass_spp_ = 1 << 30;
  int band_rows_ = 0;  // 0: not measured yet (first_band_rows)
  // Rows for one dispatch of `spp` samples per pixel before anything is measured.
  int first_band_rows(int spp) const;
  // One dispatch of rows [row_begin, row_end) into cmd (the first after a
  // reset clears the accumulation); spp_done_ unchanged. wavefront: the
  // wavefront's first stage and rounds instead; the caller submits more
  // rounds until its queues are empty (run_pass).
  void record_band(VkCommandBuffer cmd, int spp, int row_begin, int row_end, bool wavefront = false);
  // The wavefront integrator (shaders/wavefront.glsl): its stages' pipelines
  // (index: WAVEFRONT_* − 1; empty: the megakernel renders), path states and
  // queues. code: render.comp's SPIR-V, which every stage specialises.
  void create_wavefront(const std::vector<uint32_t>& code);
  void record_wavefront_start(VkCommandBuffer cmd, const gpu::PassConstants& pass);
  void record_wavefront_iterations(VkCommandBuffer cmd, int iterations);
  uint32_t wavefront_paths_left() const;
  static constexpr int kWavefrontIterations = 32;  // track + event rounds per submission
  std::vector<std::shared_ptr<const vk::ComputePipeline>> wavefront_stages_;
  vk::Buffer wavefront_paths_, wavefront_queues_;
  vk::UniqueBufferView wavefront_paths_view_;
  // Every sparse grid's NanoVDB tree and leaf table (GpuScene::sparse_blocks), read as a
  // uniform texel buffer of rgba32ui (shaders/sparse.glsl).
  vk::Buffer sparse_buffer_;
  vk::UniqueBufferView sparse_view_;
  uint32_t wavefront_capacity_ = 0;
  bool wavefront_split_ = false;
  uint64_t dropped_samples_ = 0;
  int spp_done_ = 0;
  bool needs_clear_ = true;
};

}  // namespace pyrolume
