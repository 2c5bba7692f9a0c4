// RenderSession: recording and running passes (bands, the wavefront, a pass
// the device cannot finish redone in halves).
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

namespace {
// Test hook (no CLI flag): PYROLUME_TEST_FAIL_PASS=VK_ERROR_DEVICE_LOST:N (or
// VK_ERROR_OUT_OF_DEVICE_MEMORY:N; any other name means VK_ERROR_UNKNOWN)
// makes the N-th render pass of this process (1-based) fail as if
// vkQueueSubmit had returned that result. A device cannot be lost on
// lavapipe; this is how tests reach the recovery path.
VkResult injected_failure() {
  static const std::pair<VkResult, long> fault = [] {
    const char* v = std::getenv("PYROLUME_TEST_FAIL_PASS");
    if (!v) return std::pair<VkResult, long>{VK_SUCCESS, 0};
    const std::string s = v;
    const size_t colon = s.find(':');
    const std::string name = s.substr(0, colon);
    const long n = colon == std::string::npos ? 1 : std::atol(s.c_str() + colon + 1);
    VkResult r = name == "VK_ERROR_DEVICE_LOST"            ? VK_ERROR_DEVICE_LOST
                 : name == "VK_ERROR_OUT_OF_DEVICE_MEMORY" ? VK_ERROR_OUT_OF_DEVICE_MEMORY
                                                            : VK_ERROR_UNKNOWN;
    return std::pair<VkResult, long>{r, n};
  }();
  static long passes = 0;
  if (fault.first == VK_SUCCESS) return VK_SUCCESS;
  return ++passes == fault.second ? fault.first : VK_SUCCESS;
}
}  // namespace

void RenderSession::record_pass(VkCommandBuffer cmd, int spp) {
  record_band(cmd, spp, 0, settings_.height);
  spp_done_ += spp;
}

void RenderSession::record_band(VkCommandBuffer cmd, int spp, int row_begin, int row_end, bool wavefront) {
  vkCmdFillBuffer(cmd, pass_status_.buffer(), 0, VK_WHOLE_SIZE, 0u);
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  if (needs_clear_) {
    vkCmdFillBuffer(cmd, accum_.buffer(), 0, VK_WHOLE_SIZE, 0u);
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
    needs_clear_ = false;
  }
  const gpu::PassConstants pass{uint32_t(spp_done_), uint32_t(spp), uint32_t(row_begin), uint32_t(row_end)};
  pass_constants_.record(cmd, pass);
  if (wavefront) {
    record_wavefront_start(cmd, pass);
    return;
  }
  pipeline_->bind(cmd, set_->set());
  const uint32_t groups_x = (uint32_t(settings_.width) + gpu::WORKGROUP_SIZE_X - 1) / gpu::WORKGROUP_SIZE_X;
  const uint32_t groups_y = (uint32_t(row_end - row_begin) + gpu::WORKGROUP_SIZE_Y - 1) / gpu::WORKGROUP_SIZE_Y;
  vkCmdDispatch(cmd, groups_x, groups_y, 1);
  // The next pass, a readback copy or a display shader reads what this one wrote.
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT);
}

// The guide's marches (shaders/guide.comp) over the (width + 1) × (height +
// 1) pixel corners, submitted before the first pass, which reads them. In
// bands of whole corner rows, about kGuideBandCorners corners each (tens of
// milliseconds on lavapipe), so that a signal is answered between bands and
// no dispatch runs long; each lane marches at most two rays (each at most
// GUIDE_MAX_STEPS majorant cells walked and as many steps: 4 × 4096 loop
// iterations), within llvmpipe's loop budget of 65535. False: cancelled
// between bands (the first pass then has not begun).
bool RenderSession::march_guide_points(const std::atomic<bool>* cancel) {
  const auto t0 = std::chrono::steady_clock::now();
  const uint32_t corners_x = uint32_t(settings_.width) + 1, rows = uint32_t(settings_.height) + 1;
  const uint32_t per_band = hooks_.guide_band_corners > 0 ? hooks_.guide_band_corners : kGuideBandCorners;
  const uint32_t band = std::max<uint32_t>(1, per_band / corners_x);
  bool done = true;
  for (uint32_t row = 0; row < rows; row += band) {
    if (row > 0 && cancel && cancel->load()) {
      done = false;
      break;
    }
    const uint32_t row_end = std::min(rows, row + band);
    ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
      pass_constants_.record(cmd, gpu::PassConstants{0u, 0u, row, row_end});
      // After the reads of the passes before (a kept session's earlier frame).
      vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT);
      guide_pipeline_->bind(cmd, set_->set());
      vkCmdDispatch(cmd, (corners_x + gpu::WORKGROUP_SIZE_X - 1) / gpu::WORKGROUP_SIZE_X,
                    (row_end - row + gpu::WORKGROUP_SIZE_Y - 1) / gpu::WORKGROUP_SIZE_Y, 1);
      vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT);
    });
  }
  guide_seconds_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return done;
}

// The wavefront integrator (shaders/wavefront.glsl), a benchmark and test
// hook (no scene key or flag): PYROLUME_WAVEFRONT=1 renders with its track
// and event stages, =2 with the event stage split in two (event, begin).
// It loses to the megakernel on lavapipe (docs/benchmarks.md "A wavefront
// prototype"), so nothing turns it on by default. One path slot per pixel:
// the whole image is one band, and the state must fit one texel buffer.
void RenderSession::create_wavefront(const std::vector<uint32_t>& code) {
  const char* env = std::getenv("PYROLUME_WAVEFRONT");
  const std::string mode = env ? env : "";
  // Not with analytic lights: the wavefront's path state does not carry a
  // delta light ray's target (PathState::delta_light).
  bool has_lights = false;
  for (const auto& [id, value] : spec_)
    if (id == gpu::SPEC_LIGHT_COUNT) has_lights = value > 0;
  // Nor with AOVs: its path state does not carry them.
  const bool on = (mode == "1" || mode == "2") && hooks_.debug_mode == 0 && !has_lights && !settings_.aovs;
  wavefront_split_ = on && mode == "2";
  const size_t slots = on ? size_t(settings_.width) * size_t(settings_.height) : 1;
  const size_t words = gpu::WAVEFRONT_PATH_WORDS + gpu::WAVEFRONT_PATH_WORDS_PER_MEDIUM *
                                                       std::max<size_t>(1, gpu_scene_.media.size());
  const double bytes = double(slots * words) * 16.0;
  if (slots * words > ctx_.properties().limits.maxTexelBufferElements || bytes > double(ctx_.max_allocation_size()))
    throw vk::VulkanError("PYROLUME_WAVEFRONT: " + std::to_string(settings_.width) + "x" +
                          std::to_string(settings_.height) + " pixels need " + mib(bytes) +
                          " of path state, more than this device's texel buffer holds; render a smaller image");
  wavefront_paths_ = vk::Buffer(ctx_, slots * words * 4 * sizeof(uint32_t),
                                VK_BUFFER_USAGE_STORAGE_TEXEL_BUFFER_BIT, vk::MemoryKind::DeviceLocal,
                                "wavefront paths");
  wavefront_paths_view_ = vk::texel_buffer_view(ctx_, wavefront_paths_, VK_FORMAT_R32G32B32A32_UINT);
  wavefront_queues_ = vk::Buffer(ctx_, sizeof(gpu::WavefrontQueues) + 4 * slots * sizeof(uint32_t),
                                 kStorage | VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, vk::MemoryKind::HostVisible,
                                 "wavefront queues");
  std::memset(wavefront_queues_.map(), 0, sizeof(gpu::WavefrontQueues));
  wavefront_queues_.flush();
  set_->write_texel_buffer(gpu::BINDING_PATHS, wavefront_paths_view_.get());
  set_->write_buffer(gpu::BINDING_QUEUES, wavefront_queues_);
  wavefront_capacity_ = uint32_t(slots);
  if (!on) return;
  for (uint32_t stage = gpu::WAVEFRONT_START; stage <= gpu::WAVEFRONT_SIZE_BEGIN; ++stage) {
    std::vector<std::pair<uint32_t, uint32_t>> spec = spec_;
    spec.push_back({gpu::SPEC_WAVEFRONT_STAGE, stage});
    spec.push_back({gpu::SPEC_WAVEFRONT_SPLIT, wavefront_split_ ? 1u : 0u});
    for (auto& [id, value] : spec)
      if (id == gpu::SPEC_EARLY_EVENT_EXIT)
        value = stage == gpu::WAVEFRONT_TRACK && ctx_.features().subgroup_ballot ? 1u : 0u;
    wavefront_stages_.push_back(
        ctx_.pipelines().get(code, pipeline_->bindings(), /*push_constant_bytes=*/0, spec, "render wavefront stage"));
  }
}

void RenderSession::record_wavefront_start(VkCommandBuffer cmd, const gpu::PassConstants& pass) {
  gpu::WavefrontQueues start{};
  start.capacity = wavefront_capacity_;
  vkCmdUpdateBuffer(cmd, wavefront_queues_.buffer(), 0, sizeof start, &start);
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
  const vk::ComputePipeline& start_stage = *wavefront_stages_[gpu::WAVEFRONT_START - 1];
  start_stage.bind(cmd, set_->set());
  const uint32_t groups_x = (uint32_t(settings_.width) + gpu::WORKGROUP_SIZE_X - 1) / gpu::WORKGROUP_SIZE_X;
  const uint32_t groups_y = (pass.row_end - pass.row_begin + gpu::WORKGROUP_SIZE_Y - 1) / gpu::WORKGROUP_SIZE_Y;
  vkCmdDispatch(cmd, groups_x, groups_y, 1);
  record_wavefront_iterations(cmd, kWavefrontIterations);
}

void RenderSession::record_wavefront_iterations(VkCommandBuffer cmd, int iterations) {
  auto barrier = [&] {
    vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                       VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_DRAW_INDIRECT_BIT,
                       VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_INDIRECT_COMMAND_READ_BIT);
  };
  auto stage = [&](uint32_t s) -> const vk::ComputePipeline& { return *wavefront_stages_[s - 1]; };
  // The stages' layouts are identically defined, so the set stays bound
  // across their pipelines: bound once. The pass's constants stay in their
  // buffer (record_band wrote them).
  stage(gpu::WAVEFRONT_TRACK).bind(cmd, set_->set());
  // A queue stage: its one-lane sizing stage, then the stage itself, as large as its queue.
  auto run = [&](uint32_t sizing, uint32_t queued, VkDeviceSize dispatch_offset) {
    barrier();
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, stage(sizing).pipeline());
    vkCmdDispatch(cmd, 1, 1, 1);
    barrier();
    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, stage(queued).pipeline());
    vkCmdDispatchIndirect(cmd, wavefront_queues_.buffer(), dispatch_offset);
  };
  for (int i = 0; i < iterations; ++i) {
    run(gpu::WAVEFRONT_SIZE_TRACK, gpu::WAVEFRONT_TRACK, offsetof(gpu::WavefrontQueues, track_dispatch));
    run(gpu::WAVEFRONT_SIZE_EVENT, gpu::WAVEFRONT_EVENT, offsetof(gpu::WavefrontQueues, event_dispatch));
    if (wavefront_split_)
      run(gpu::WAVEFRONT_SIZE_BEGIN, gpu::WAVEFRONT_BEGIN, offsetof(gpu::WavefrontQueues, begin_dispatch));
  }
  vk::memory_barrier(cmd, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                     VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT | VK_PIPELINE_STAGE_HOST_BIT,
                     VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT |
                         VK_ACCESS_HOST_READ_BIT);
}

// Paths still queued for the track stage after the last recorded iteration.
uint32_t RenderSession::wavefront_paths_left() const {
  wavefront_queues_.invalidate();
  const gpu::WavefrontQueues* q = wavefront_queues_.data<gpu::WavefrontQueues>();
  return (q->track_read ^ 1u) == 0u ? q->track_count0 : q->track_count1;
}

int RenderSession::first_band_rows(int spp) const {
  // About 2^14 paths: a few milliseconds for an ordinary scene, and bounded
  // for a pathological one (on llvmpipe each invocation stops after 65535
  // loop iterations, PassStatus); band_rows_ then adapts to what was measured.
  const int64_t rows = (int64_t(1) << 14) / std::max<int64_t>(1, int64_t(settings_.width) * spp);
  return int(std::clamp<int64_t>(rows, 1, settings_.height));
}

bool RenderSession::run_pass(int spp, const std::atomic<bool>* cancel) {
  // What the accumulation holds after the last sub-pass that completed: a
  // failure restores it, so the counters never claim samples it lacks.
  int spp_ok = spp_done_;
  bool clear_ok = needs_clear_;
  const VkBufferCopy all{0, 0, accum_.size()};
  // The accumulation as it was before the pass in flight (a pass that cleared
  // it just needs clearing again).
  auto restore = [&](bool clears) {
    if (clears) {
      needs_clear_ = true;
      return;
    }
    ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
      vkCmdCopyBuffer(cmd, accum_backup_.buffer(), accum_.buffer(), 1, &all);
      vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                         VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                         VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_READ_BIT);
    });
  };
  try {
    if (VkResult r = injected_failure(); r != VK_SUCCESS)
      vk::throw_vk_error("vkQueueSubmit (PYROLUME_TEST_FAIL_PASS)", r, __FILE__, __LINE__);
    // A pass the device cannot finish (llvmpipe's loop budget, PassStatus) is
    // undone from the copy taken before it and redone in halves; the size that
    // works is kept for the passes after it. Each sample keeps its index, so
    // the result is the same as with passes that fit, and as with one dispatch
    // for the whole image: the bands below only split the pixels.
    const bool wavefront = !wavefront_stages_.empty();
    // The guide is marched in a pass's first samples (sample_offset 0).
    if (settings_.aovs && spp_done_ == 0 && !march_guide_points(cancel)) return false;
    for (int remaining = spp; remaining > 0;) {
      const int n = std::min(remaining, max_pass_spp_);
      const bool clears = needs_clear_;
      if (band_rows_ == 0) band_rows_ = first_band_rows(n);
      uint32_t unfinished = 0;
      bool interrupted = false;
      for (int row = 0; row < settings_.height;) {
        // The wavefront keeps every pixel's path in flight at once: one band.
        const int rows = wavefront ? settings_.height - row : std::min(band_rows_, settings_.height - row);
        const bool first_band = row == 0;
        const auto t0 = std::chrono::steady_clock::now();
        ctx_.submit_and_wait([&](VkCommandBuffer cmd) {
          if (first_band && !clears) {
            vkCmdCopyBuffer(cmd, accum_.buffer(), accum_backup_.buffer(), 1, &all);
            vk::memory_barrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_READ_BIT,
                               VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT);
          }
          record_band(cmd, n, row, row + rows, wavefront);
        });
        // The wavefront: more rounds until no path is left in its queues (a
        // signal drops the pass; the next one starts on fresh queues).
        while (wavefront && wavefront_paths_left() > 0) {
          if (cancel && cancel->load()) {
            interrupted = true;
            break;
          }
          ctx_.submit_and_wait([&](VkCommandBuffer cmd) { record_wavefront_iterations(cmd, kWavefrontIterations); });
        }
        if (interrupted) break;
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        pass_status_.invalidate();
        unfinished += pass_status_.data<gpu::PassStatus>()->unfinished_samples;
        row += rows;
        // Dispatches long enough to hide their overhead, short enough that a
        // signal is answered at once and no GPU watchdog fires.
        if (seconds < kBandFastSeconds) band_rows_ = std::min(settings_.height, band_rows_ * 2);
        else if (seconds > kBandSlowSeconds) band_rows_ = std::max(1, band_rows_ / 2);
        if (row < settings_.height && cancel && cancel->load()) {
          interrupted = true;
          break;
        }
        if (unfinished > 0 && n > 1) break;  // redone in halves anyway: the other bands would be wasted
      }
      if (interrupted) {
        restore(clears);
        spp_ok = spp_done_;
        clear_ok = needs_clear_;
        return false;
      }
      if (unfinished == 0 || n == 1) {
        dropped_samples_ += unfinished;  // at 1 spp per pass there is nothing left to split
        spp_done_ += n;
        remaining -= n;
        spp_ok = spp_done_;
        clear_ok = needs_clear_;
        continue;
      }
      restore(clears);
      max_pass_spp_ = n / 2;
    }
  } catch (const vk::VulkanError&) {
    spp_done_ = spp_ok;
    needs_clear_ = clear_ok;
    throw;
  }
  return true;
}

}  // namespace pyrolume
