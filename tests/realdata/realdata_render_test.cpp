// Each real export in the shared data folder rendered at low
// resolution on the Vulkan backend and on the CPU reference, compared
// statistically (issue 4 "Real data", issue 5 "GPU vs CPU ... on each real VDB"):
// per-pixel z-test on 3×3-pooled variances (>= 99.75 % within 4σ) and the
// bias formula of docs/testing.md. Files are read in place, never copied; when the
// folder is absent the tests say so and skip.
#include <chrono>
#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "backends/Backends.h"
#include "render/SceneSetup.h"
#include "render/cpu/CpuRenderer.h"
#include "scene/MediumVolume.h"
#include "support/AnalyticScenes.h"
#include "support/LightScenes.h"
#include "support/Stats.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "volume/StoredVolume.h"

namespace pyrolume {
namespace {

namespace fs = std::filesystem;

using test::settings_for;

class RealRender : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (test::real_vdb_dir().empty()) return;
    BackendOptions o;
    o.validation = true;
    backend_ = make_backend("vulkan", o);
  }
  static void TearDownTestSuite() { backend_.reset(); }

  void SetUp() override {
    dir = test::real_vdb_dir();
    if (dir.empty()) GTEST_SKIP() << test::kRealVdbAbsent;
  }
  void TearDown() override {
    if (backend_) EXPECT_EQ(backend_->validation_messages(), 0u) << "Vulkan validation reported problems";
  }

  // A medium glowing from its temperature grid (emit_blackbody below),
  // framed z up from −y at w × h pixels over `background`, max_depth 4.
  Scene framed_glowing(Medium m, const char* temperature_grid, double scale, double temperature_scale, int w, int h,
                       glm::dvec3 background);

  // A scene that frames the medium's world bounds (from the stored density
  // grid, as the renderers clip rays), seen from −view_axis with `up`.
  Scene framed(const Medium& m, glm::dvec3 view_axis, glm::dvec3 up, int w, int h) {
    const StoredVolume v = load_stored_volume(m);
    glm::dvec3 lo, hi;
    v.density.grid.world_bounds(lo, hi);
    const glm::dvec3 c = 0.5 * (lo + hi), ext = hi - lo;
    Scene s;
    s.file = "<realdata>";
    s.film.width = w;
    s.film.height = h;
    s.film.seed = 1;
    s.camera.fov_deg = 40.0;
    s.camera.up = up;
    const double depth = std::abs(glm::dot(ext, view_axis));
    const double across = std::max(std::abs(glm::dot(ext, up)), glm::length(ext - glm::dot(ext, view_axis) * view_axis -
                                                                              glm::dot(ext, up) * up));
    const double dist = 0.5 * depth + 0.55 * across / std::tan(glm::radians(20.0));
    s.camera.position = c - dist * view_axis;
    s.camera.look_at = c;
    s.media.push_back(m);
    std::printf("%s: world bounds (%.3f %.3f %.3f)-(%.3f %.3f %.3f), dense %dx%dx%d\n", m.file.filename().c_str(),
                lo.x, lo.y, lo.z, hi.x, hi.y, hi.z, v.density.grid.dims.x, v.density.grid.dims.y,
                v.density.grid.dims.z);
    return s;
  }

  // The Houdini smoke plume (density only, max 5.71, y up), emitting
  // nothing, seen along −z at 24 × 32 with four bounces, before `background`.
  Scene houdini_plume(Medium m, const glm::dvec3& background) {
    m.emission.scale = 0.0;
    Scene s = framed(m, {0, 0, 1}, {0, 1, 0}, 24, 32);
    s.background = background;
    s.integrator.max_depth = 4;
    return s;
  }

  // GPU at gpu_spp vs CPU at cpu_spp (independent seeds). informative: the
  // image-mean bias test must have an SE below half its tolerance.
  void compare(Scene s, int gpu_spp, int cpu_spp, const char* what, bool informative = true) {
    s.film.spp = gpu_spp;
    s.film.seed = 1;
    RenderResult gpu = backend_->render(s, settings_for(s), {});
    EXPECT_EQ(gpu.nonfinite_samples, 0u);
    s.film.spp = cpu_spp;
    s.film.seed = 2;
    CpuRenderer cpu;
    const auto t0 = std::chrono::steady_clock::now();
    RenderResult ref = cpu.render(s, settings_for(s), {});
    const double cpu_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_EQ(cpu.majorant_violations(), 0u);
    EXPECT_EQ(ref.nonfinite_samples, 0u);
    double total = 0.0;
    for (double x : ref.sum) total += x;
    EXPECT_GT(total, 0.0) << what << ": the CPU image is black";
    test::ZTestOptions o;
    o.pool3x3 = true;
    o.require_informative = informative;
    test::ZTestReport rep = test::ztest_images(gpu, ref, o);
    EXPECT_TRUE(rep.ok) << what << ": " << rep.summary();
    std::printf("%s GPU vs CPU: %s; GPU %.2f s (load %.2f s), CPU %.2f s; GPU lookups/sample %.2f\n", what,
                rep.summary().c_str(), gpu.seconds, gpu.load_seconds, cpu_s,
                gpu.density_lookups / (double(gpu.width) * gpu.height * gpu.spp));
  }

  static std::unique_ptr<Backend> backend_;
  fs::path dir;
};
std::unique_ptr<Backend> RealRender::backend_;

// The medium of `file`'s "density" grid.
Medium vdb(const fs::path& file, glm::dvec3 sigma_a, glm::dvec3 sigma_s, double g) {
  return test::vdb_density_medium(file.stem().string(), file, sigma_a, sigma_s, g);
}

// Blackbody emission (seed normalisation) times `scale` from the grid
// `temperature_grid`, its values mapped to kelvin by temperature_scale with
// a cutoff of 600 K.
void emit_blackbody(Medium& m, const char* temperature_grid, double scale, double temperature_scale) {
  m.temperature_grid = temperature_grid;
  m.emission.is_grid = true;
  m.emission.scale = scale;
  m.emission.blackbody = BlackbodyMode::Seed;
  m.temperature.scale = temperature_scale;
  m.temperature.cutoff_k = 600.0;
}

Scene RealRender::framed_glowing(Medium m, const char* temperature_grid, double scale, double temperature_scale,
                                 int w, int h, glm::dvec3 background) {
  emit_blackbody(m, temperature_grid, scale, temperature_scale);
  Scene s = framed(m, {0, 1, 0}, {0, 0, 1}, w, h);
  s.background = background;
  s.integrator.max_depth = 4;
  return s;
}

// The plume has no temperature grid, so it is lit by the background (rgb 1)
// through scattering.
TEST_F(RealRender, HoudiniSmokeLitByBackground) {
  Medium m = vdb(dir / "openvdb_smoke1_houdini.vdb", {0.15, 0.2, 0.25}, {0.45, 0.45, 0.45}, 0.3);
  compare(houdini_plume(m, {1.0, 1.0, 1.0}), 1024, 96, "houdini smoke");
}

// The same plume kept sparse (texture_format "sparse", issue 26): the GPU
// reads the NanoVDB tree through its leaf table, the CPU through NanoVDB's
// accessor, and the two agree.
TEST_F(RealRender, HoudiniSmokeKeptSparse) {
  Medium m = vdb(dir / "openvdb_smoke1_houdini.vdb", {0.15, 0.2, 0.25}, {0.45, 0.45, 0.45}, 0.3);
  m.texture_format = TextureFormat::Sparse;
  compare(houdini_plume(m, {1.0, 1.0, 1.0}), 1024, 96, "houdini smoke, sparse");
}

// The same plume lit by a low sun (issue 24): a disc of 0.53° and irradiance
// 3, under a dim sky, at 32 spp on both backends. The sun reaches the smoke
// only by next-event estimation through ratio-tracked light rays; rays that
// escape inside its disc add its radiance, MIS-weighted.
TEST_F(RealRender, HoudiniSmokeLitBySun) {
  Medium m = vdb(dir / "openvdb_smoke1_houdini.vdb", {0.1, 0.1, 0.1}, {1.2, 1.2, 1.2}, 0.4);
  Scene s = houdini_plume(m, {0.05, 0.07, 0.1});
  s.lights.push_back(test::distant_light({-1.0, 0.3, 0.5}, {3.0, 2.8, 2.5}, 0.53));
  // The per-pixel criterion at 32 spp (issue 24); the image mean's bias
  // needs more samples to say anything (SE 0.4 % at 32 spp).
  compare(s, 32, 32, "houdini smoke under a sun, 32 spp", false);
  compare(s, 256, 256, "houdini smoke under a sun, 256 spp");
}

// Blender 2.79 fire: density (max 0.19) and `heat` (dimensionless, max 1.57)
// mapped to kelvin by scale 1500 with cutoff 600 K; z up, non-uniform voxels.
TEST_F(RealRender, Blender279FireWithHeat) {
  Scene s = framed_glowing(vdb(dir / "blender279_fire_frame075.vdb", {1.0, 1.0, 1.0}, {0.5, 0.5, 0.5}, 0.2), "heat", 4.0,
                           1500.0, 20, 32, {0.05, 0.05, 0.08});
  s.integrator.emission_estimator = EmissionEstimator::Collision;
  compare(s, 4096, 1536, "blender 2.79 fire");
}

// The thin, hot version of the same fire as a user writes it (issue 23):
// density ×0.02, emission ×100, everything else the file's and the scene
// defaults', camera framed automatically. "auto" picks the line estimator on
// both backends, and they agree pixel by pixel.
TEST_F(RealRender, ThinHotBlenderFireWithTheDefaultEstimator) {
  const std::string text = R"({"media": [{"type": "vdb", "file": ")" +
                           (dir / "blender279_fire_frame075.vdb").string() +
                           R"(", "density_scale": 0.02, "emission": {"scale": 100}}],
                              "film": {"width": 32, "height": 48}})";
  Scene s = parse_scene(text, "thin_fire.json");
  complete_scene(s, true);
  s.film.spp = 64;
  const RenderResult g = backend_->render(s, settings_for(s), {});
  EXPECT_EQ(g.emission_estimator, "line");
  CpuRenderer cpu;
  EXPECT_EQ(cpu.render(s, RenderSettings{.width = 4, .height = 4, .spp = 1}, {}).emission_estimator, "line");
  compare(s, 2048, 1024, "thin hot blender 2.79 fire, default estimator");
}

// Blender 5.0 Mantaflow smoke, tiny (14×14×15 active voxels), z up, all
// grids half; its `temperature` is a constant 1.97 at this frame: ×1000 K
// gives ~1975 K emission.
TEST_F(RealRender, MantaflowSmokeWithTemperature) {
  compare(framed_glowing(vdb(dir / "blender50_mantaflow_smoke_frame0001.vdb", {2.0, 2.0, 2.0}, {1.5, 1.5, 1.5}, 0.0),
                         "temperature", 3.0, 1000.0, 32, 32, {0.1, 0.1, 0.15}),
          2048, 256, "mantaflow smoke");
}

}  // namespace
}  // namespace pyrolume
