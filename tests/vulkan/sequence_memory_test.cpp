// A long sequence runs at constant memory (issue 45 item 8). lavapipe (Mesa
// 22.x) inlines push-constant and uniform-block values that alone decide a
// branch or a loop count and JIT-compiles a new variant of the shader every
// time a command buffer binds them, never freed: ~0.5 MB and a compile per
// pass, so `render --frames` grew until the address space ran out (SIGSEGV at
// frame ~2710 under a 2 GiB limit). Each Vulkan scene below reaches one of
// the blocks that were inlined: the media, and the frame (frame.p_env > 0
// decides a branch with an environment and MIS).
// The frames are rendered as `render --frames` renders them: one backend, its
// session kept from frame to frame.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <string>

#include "backends/Backends.h"
#include "support/MisScenes.h"
#include "support/TestSupport.h"

using namespace pyrolume;
using namespace pyrolume::test;

namespace {

// This process's resident memory in MiB (/proc/self/status VmRSS).
double rss_mib() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  ADD_FAILURE() << "no VmRSS in /proc/self/status";
  return 0.0;
}

// An 8×8, 1-spp frame per pass: the shape of a long farm sequence at its smallest.
Scene tiny(Scene s) {
  s.film.width = 8;
  s.film.height = 8;
  s.film.spp = 1;
  s.integrator.max_depth = 4;
  return s;
}

// The media block: an emissive scattering sphere.
Scene ember_scene() {
  Scene s = analytic_base_scene(8, 8, 1);
  s.media.push_back(
      homogeneous_sphere("ember", {0, 0, 0}, 1.0, glm::dvec3(0.6), glm::dvec3(1.2), 0.3, glm::dvec3(1, 0.75, 0.4), 2.0));
  return tiny(s);
}

// The frame block: a diffuse sphere in a uniform sky, next-event estimation with MIS.
Scene sky_scene(const std::filesystem::path& dir) { return tiny(furnace_sphere_scene(dir, Strategy::Mis, 1)); }

// How much the resident memory grows over `frames` frames once `warm_up`
// frames have run (the allocator's and the driver's first-use growth).
double growth_mib(const std::string& backend_name, const Scene& scene, int warm_up, int frames) {
  BackendOptions options;
  options.frame_reuse = true;  // as render --frames
  auto backend = make_backend(backend_name, options);
  RenderSettings settings;
  settings.width = scene.film.width;
  settings.height = scene.film.height;
  settings.spp = scene.film.spp;
  auto render = [&](int frame) {
    settings.frame = uint32_t(frame);
    const RenderResult r = backend->render(scene, settings, {});
    EXPECT_EQ(r.spp, 1);
  };
  int frame = 1;
  for (; frame <= warm_up; ++frame) render(frame);
  const double before = rss_mib();
  for (; frame <= warm_up + frames; ++frame) render(frame);
  const double after = rss_mib();
  EXPECT_EQ(backend->validation_messages(), 0u);
  std::printf("%s: %.1f MiB resident after %d frames, %+.2f MiB over the next %d\n", backend_name.c_str(), before,
              warm_up, after - before, frames);
  return after - before;
}

// 200 frames: before the fix they grew by ~100 MiB. 4 MiB leaves room for
// the allocator's noise and is still ~20 KiB a frame.
constexpr int kWarmUp = 30, kFrames = 200;
constexpr double kBoundMib = 4.0;

}  // namespace

TEST(SequenceMemory, VulkanMediaSequenceRunsAtConstantMemory) {
  EXPECT_LT(growth_mib("vulkan", ember_scene(), kWarmUp, kFrames), kBoundMib);
}

TEST(SequenceMemory, VulkanSkySequenceRunsAtConstantMemory) {
  EXPECT_LT(growth_mib("vulkan", sky_scene(temp_dir("seq-memory-sky")), kWarmUp, kFrames), kBoundMib);
}

TEST(SequenceMemory, CpuSequenceRunsAtConstantMemory) {
  EXPECT_LT(growth_mib("cpu", ember_scene(), kWarmUp, kFrames), kBoundMib);
}
