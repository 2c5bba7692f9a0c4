// RenderSession: the sums read back, and the accumulation as checkpoint state.
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

AccumulationState RenderSession::save_state() {
  const size_t pixels = size_t(settings_.width) * size_t(settings_.height);
  AccumulationState st;
  st.backend = "vulkan";
  st.width = settings_.width;
  st.height = settings_.height;
  st.spp = spp_done_;
  // The AccumTexels, then the AlphaTexels (without the alignment gap between them on the device).
  const size_t texels = pixels * sizeof(gpu::AccumTexel);
  st.data.assign(texels + pixels * sizeof(gpu::AlphaTexel), 0);
  if (spp_done_ > 0 && !needs_clear_) {
    accum_.download(ctx_, st.data.data(), texels);
    accum_.download(ctx_, st.data.data() + texels, st.data.size() - texels, alpha_offset_);
  }
  return st;
}

void RenderSession::load_state(const AccumulationState& st) {
  const size_t texels = accumulation_texel_bytes(),
               bytes = texels + size_t(settings_.width) * size_t(settings_.height) * sizeof(gpu::AlphaTexel);
  if (st.backend != "vulkan" || st.width != settings_.width || st.height != settings_.height ||
      st.data.size() != bytes || st.spp < 0)
    throw std::invalid_argument("vulkan: the resumed accumulation is not a " + std::to_string(settings_.width) + "x" +
                                std::to_string(settings_.height) + " vulkan one");
  accum_.upload(ctx_, st.data.data(), texels);
  accum_.upload(ctx_, st.data.data() + texels, bytes - texels, alpha_offset_);
  spp_done_ = st.spp;
  needs_clear_ = st.spp == 0;
}

void RenderSession::read(RenderResult& result) {
  result_from_state(save_state(), result);
  read_aovs(result);
}

void RenderSession::read_aovs(RenderResult& result) {
  result.aov_sum.clear();
  if (!settings_.aovs) return;
  const size_t pixels = size_t(settings_.width) * size_t(settings_.height);
  result.aov_sum.assign(pixels * kAovValues, 0.0);
  if (spp_done_ <= 0 || needs_clear_) return;
  // Both layers, read in place where the buffer is host memory (no copy of
  // ~100 bytes a pixel), else copied out.
  const VkDeviceSize aov_bytes = aov_features_offset_ + pixels * sizeof(gpu::AovFeatureTexel) - aov_lights_offset_;
  std::vector<unsigned char> copy;
  const unsigned char* aovs = static_cast<const unsigned char*>(accum_.read_in_place(ctx_, aov_bytes, aov_lights_offset_));
  if (!aovs) {
    copy.resize(aov_bytes);
    accum_.download(ctx_, copy.data(), aov_bytes, aov_lights_offset_);
    aovs = copy.data();
  }
  const unsigned char* features_at = aovs + (aov_features_offset_ - aov_lights_offset_);
  for (size_t i = 0; i < pixels; ++i) {
    double* s = result.aov_sum.data() + i * kAovValues;
    gpu::AovLightTexel l;
    gpu::AovFeatureTexel f;
    std::memcpy(&l, aovs + i * sizeof l, sizeof l);
    std::memcpy(&f, features_at + i * sizeof f, sizeof f);
    for (int c = 0; c < 3; ++c) {
      s[kAovEmission + c] = l.emission[c];
      s[kAovScatter + c] = l.scatter[c];
      s[kAovSurface + c] = l.surface[c];
      s[kAovBackground + c] = l.background[c];
      s[kAovAlbedo + c] = f.albedo[c];
      s[kAovNormal + c] = f.normal[c];
      s[kAovGuide + c] = f.guide[c];
    }
    s[kAovDepth] = f.depth;
    s[kAovHits] = f.hits;
    s[kAovGuideAlpha] = f.guide_alpha;
  }
}

void RenderSession::result_from_state(const AccumulationState& state, RenderResult& result) {
  const size_t pixels = size_t(state.width) * size_t(state.height);
  if (state.data.size() != pixels * (sizeof(gpu::AccumTexel) + sizeof(gpu::AlphaTexel)))
    throw std::logic_error("RenderSession::result_from_state: state size does not match its image");
  result.width = state.width;
  result.height = state.height;
  result.spp = state.spp;
  result.sum.assign(pixels * 3, 0.0);
  result.sum_sq.assign(pixels * 3, 0.0);
  result.alpha_sum.assign(pixels, 0.0);
  result.alpha_sum_sq.assign(pixels, 0.0);
  result.events = result.density_lookups = 0.0;
  result.nonfinite_samples = 0;
  for (size_t i = 0; i < pixels; ++i) {
    gpu::AccumTexel t;
    std::memcpy(&t, state.data.data() + i * sizeof t, sizeof t);
    for (int c = 0; c < 3; ++c) {
      // Kahan: the running sum minus its pending compensation.
      result.sum[i * 3 + c] = double(t.sum[c]) - double(t.sum_c[c]);
      result.sum_sq[i * 3 + c] = double(t.sum_sq[c]) - double(t.sum_sq_c[c]);
    }
    gpu::AlphaTexel a;
    std::memcpy(&a, state.data.data() + pixels * sizeof t + i * sizeof a, sizeof a);
    result.alpha_sum[i] = double(a.sum) - double(a.sum_c);
    result.alpha_sum_sq[i] = double(a.sq) - double(a.sq_c);
    result.events += double(t.events) - double(t.events_c);
    result.density_lookups += double(t.lookups);
    result.nonfinite_samples += uint64_t(t.nonfinite);
  }
}

}  // namespace pyrolume
