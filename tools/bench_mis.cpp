// bench_mis: what next-event estimation + MIS buys on a scene where a fire
// lights surfaces (issue 6 "Speed and accuracy"; docs/mis.md). Measured on the
// pixels that show lit terrain, not on pixels that see the fire or the sky.
//
//   bench_mis [SCENE.json] [--backend vulkan|cpu] [--width W] [--height H]
//             [--spp N] [--reps R] [--ref-spp N] [--mask-spp N]
//
// Default scene: assets/scenes/terrain_explosion.json. Prints a markdown table
// (stdout) and progress (stderr). For each strategy (MIS, BSDF/phase sampling
// only), R renders of N spp with different seeds:
//   - variance: the mean over terrain pixel-channels of the per-pixel variance
//     of one sample (from the render's own sums), median over the reps;
//   - relMSE against a reference (MIS, ref-spp, another seed) over the terrain
//     pixels (the pbrt/Mitsuba relMSE of host/image/Compare.h), median;
//   - seconds (first dispatch to readback), median;
//   - efficiency 1 / (relMSE · seconds), and the MIS/BSDF ratios at equal spp
//     and at equal time (relMSE ∝ 1/time for an unbiased estimator).
// Terrain pixels: camera rays that hit a surface (a render with no media, no
// environment, background 1 and max_depth 0 is 0 there) and whose camera ray
// meets no medium before it (a render with the media as pure absorbers, no
// surfaces, background 1 is 1 there): both to within 1e-3 at mask-spp.
// BENCH_MIS_MAPS=DIR also renders each strategy once more (seed 7) and writes
// DIR/sd_{mis,bsdf}.png (per-pixel standard deviation of one sample, terrain
// tinted blue) and DIR/var_{mis,bsdf}.f32 (raw float32, width × height × 3:
// per-sample variance averaged over the channels, mean, terrain mask), for
// finding the pixels that hold the variance.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "backends/Backends.h"
#include "image/ImageIo.h"
#include "render/SceneSetup.h"
#include "scene/Scene.h"

using namespace pyrolume;

namespace {

struct Options {
  std::string scene = std::string(PYROLUME_SOURCE_DIR) + "/assets/scenes/terrain_explosion.json";
  std::string backend = "vulkan";
  int width = 160, height = 90, spp = 64, reps = 3, ref_spp = 2048, mask_spp = 16;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      return argv[++i];
    };
    if (a == "--backend") o.backend = next();
    else if (a == "--width") o.width = std::stoi(next());
    else if (a == "--height") o.height = std::stoi(next());
    else if (a == "--spp") o.spp = std::stoi(next());
    else if (a == "--reps") o.reps = std::stoi(next());
    else if (a == "--ref-spp") o.ref_spp = std::stoi(next());
    else if (a == "--mask-spp") o.mask_spp = std::stoi(next());
    else if (a == "-h" || a == "--help") {
      std::printf("bench_mis [SCENE.json] [--backend vulkan|cpu] [--width W] [--height H] [--spp N] [--reps R] "
                  "[--ref-spp N] [--mask-spp N]\n");
      std::exit(0);
    } else if (!a.empty() && a[0] != '-') o.scene = a;
    else throw std::invalid_argument("unknown option " + a);
  }
  return o;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Strategy {
  const char* name;
  bool mis;
};

}  // namespace

int main(int argc, char** argv) try {
  const Options o = parse(argc, argv);
  Scene base = load_scene(o.scene);
  complete_scene(base, true);  // source conventions and framing, as `render` settles them
  auto backend = make_backend(o.backend);
  auto render = [&](const Scene& s, int spp, uint32_t seed) {
    RenderSettings rs;
    rs.width = o.width;
    rs.height = o.height;
    rs.spp = spp;
    rs.seed = seed;
    return backend->render(s, rs, {});
  };
  auto mean = [](const RenderResult& r, size_t i) { return r.sum[i] / r.spp; };

  // Terrain mask.
  Scene surfaces_only = base;
  surfaces_only.media.clear();
  surfaces_only.environment.reset();
  surfaces_only.background = glm::dvec3(1.0);
  surfaces_only.integrator.max_depth = 0;
  Scene media_only = base;
  media_only.shapes.clear();
  media_only.environment.reset();
  media_only.background = glm::dvec3(1.0);
  media_only.integrator.max_depth = 0;
  for (Medium& m : media_only.media) {
    m.sigma_a = glm::dvec3(50.0);
    m.sigma_s = glm::dvec3(0.0);
    m.emission.scale = 0.0;
  }
  std::fprintf(stderr, "bench_mis: masks ...\n");
  const RenderResult ms = render(surfaces_only, o.mask_spp, 1), mm = render(media_only, o.mask_spp, 1);
  const size_t pixels = size_t(o.width) * o.height;
  std::vector<size_t> terrain;
  for (size_t p = 0; p < pixels; ++p)
    if (mean(ms, p * 3) < 1e-3 && mean(mm, p * 3) > 1.0 - 1e-3) terrain.push_back(p);
  if (terrain.empty()) throw std::runtime_error("no terrain pixels in " + o.scene);

  auto with = [&](bool mis) {
    Scene s = base;
    s.integrator.mis = mis;
    s.integrator.emission_estimator = EmissionEstimator::Collision;
    s.integrator.light_only = mis && std::getenv("BENCH_MIS_LIGHT_ONLY");
    return s;
  };
  std::fprintf(stderr, "bench_mis: reference, MIS, %d spp ...\n", o.ref_spp);
  const RenderResult ref = render(with(true), o.ref_spp, 1000);
  if (const char* maps = std::getenv("BENCH_MIS_MAPS")) {  // diagnostics: per-pixel variance, MIS and BSDF
    for (bool mis : {true, false}) {
      const RenderResult r = render(with(mis), o.spp, 7);
      Image img = make_image(o.width, o.height);
      for (size_t i = 0; i < pixels * 3; ++i) {
        const double m = r.sum[i] / r.spp;
        img.rgb[i] = float(std::sqrt(std::max(0.0, (r.sum_sq[i] - r.spp * m * m) / (r.spp - 1))));
      }
      // Raw float32 figures for analysis (width × height × 3): per-sample variance (channel mean), mean, terrain mask.
      Image raw = make_image(o.width, o.height);
      for (size_t p = 0; p < pixels; ++p)
        for (int c = 0; c < 3; ++c) {
          raw.rgb[p * 3] += img.rgb[p * 3 + c] * img.rgb[p * 3 + c] / 3.0f;
          raw.rgb[p * 3 + 1] += float(r.sum[p * 3 + c] / r.spp / 3.0);
        }
      for (size_t p : terrain) raw.rgb[p * 3 + 2] = 1.0f;
      std::ofstream(std::string(maps) + (mis ? "/var_mis.f32" : "/var_bsdf.f32"), std::ios::binary)
          .write(reinterpret_cast<const char*>(raw.rgb.data()), std::streamsize(raw.rgb.size() * sizeof(float)));
      for (size_t p : terrain) img.rgb[p * 3 + 2] += 0.05f;
      write_image(std::string(maps) + (mis ? "/sd_mis.png" : "/sd_bsdf.png"), img);
    }
  }

  // Variance per sample and relative variance Σvar/Σmean² over the terrain pixel-channels.
  auto terrain_variance = [&](const RenderResult& r, double* relative) {
    double v = 0.0, m2 = 0.0;
    for (size_t p : terrain)
      for (int c = 0; c < 3; ++c) {
        const size_t i = p * 3 + c;
        const double m = r.sum[i] / r.spp;
        v += std::max(0.0, (r.sum_sq[i] - r.spp * m * m) / (r.spp - 1));
        m2 += m * m;
      }
    if (relative) *relative = m2 > 0.0 ? v / m2 : 0.0;
    return v / (3.0 * terrain.size());
  };

  // The pixel-footprint floor: what the texture and the geometry inside each
  // pixel add whatever the lighting. Direct light from a uniform white sky by
  // BSDF sampling (no media), whose irradiance varies only with occlusion.
  double floor_relative = 0.0;
  {
    Scene white = base;
    white.media.clear();
    white.integrator.max_depth = 1;
    white.integrator.mis = false;
    const auto sky = std::filesystem::temp_directory_path() / ("bench_mis_white_" + std::to_string(getpid()) + ".exr");
    Image img = make_image(8, 4);
    for (float& v : img.rgb) v = 1.0f;
    write_image(sky, img);
    white.environment = Environment{sky, 1.0, 0.0};
    std::fprintf(stderr, "bench_mis: footprint floor ...\n");
    terrain_variance(render(white, o.spp, 1), &floor_relative);
    std::filesystem::remove(sky);
  }

  struct Row {
    double variance, relative, rel_mse, seconds;
    double variance_all;  // per sample, from all reps' samples of each pixel together (reps·spp)
  };
  std::vector<Row> rows;
  const Strategy strategies[] = {{"MIS", true}, {"BSDF/phase only", false}};
  for (const Strategy& k : strategies) {
    std::vector<double> var, relv, rel, sec;
    RenderResult all;  // every rep's samples: one estimate of each pixel's variance from reps·spp samples
    all.spp = 0;
    all.sum.assign(pixels * 3, 0.0);
    all.sum_sq.assign(pixels * 3, 0.0);
    for (int rep = 0; rep < o.reps; ++rep) {
      std::fprintf(stderr, "bench_mis: %s, %d spp, rep %d ...\n", k.name, o.spp, rep + 1);
      const RenderResult r = render(with(k.mis), o.spp, uint32_t(1 + rep));
      double e = 0.0, relative = 0.0;
      for (size_t p : terrain)
        for (int c = 0; c < 3; ++c) {
          const size_t i = p * 3 + c;
          const double m = r.sum[i] / r.spp, b = ref.sum[i] / ref.spp;
          e += (m - b) * (m - b) / (b * b + 1e-2);
        }
      all.spp += r.spp;
      for (size_t i = 0; i < pixels * 3; ++i) {
        all.sum[i] += r.sum[i];
        all.sum_sq[i] += r.sum_sq[i];
      }
      var.push_back(terrain_variance(r, &relative));
      relv.push_back(relative);
      rel.push_back(e / (3.0 * terrain.size()));
      sec.push_back(r.seconds);
    }
    rows.push_back({median(var), median(relv), median(rel), median(sec), terrain_variance(all, nullptr)});
  }

  const Row& m = rows[0];
  const Row& b = rows[1];
  std::printf("%s, %s on %s, %dx%d, %d spp, %d reps (medians); %zu terrain pixels of %zu; reference MIS %d spp.\n\n",
              o.scene.substr(o.scene.find_last_of('/') + 1).c_str(), backend->name().c_str(),
              backend->device_name().c_str(), o.width, o.height, o.spp, o.reps, terrain.size(), pixels, o.ref_spp);
  std::printf("| strategy | terrain variance per sample | relative variance Σvar/Σmean² | terrain relMSE | seconds | "
              "efficiency 1/(relMSE·s) |\n");
  std::printf("| --- | --- | --- | --- | --- | --- |\n");
  for (size_t i = 0; i < rows.size(); ++i)
    std::printf("| %s | %.4g | %.4g | %.4g | %.3g | %.4g |\n", strategies[i].name, rows[i].variance, rows[i].relative,
                rows[i].rel_mse, rows[i].seconds, 1.0 / (rows[i].rel_mse * rows[i].seconds));
  std::printf("| footprint floor (white sky, direct, no media) | | %.4g | | | |\n", floor_relative);
  std::printf("\nMIS vs BSDF only: variance at equal spp %.2f× lower; above the footprint floor %.2f× lower; relMSE at "
              "equal spp %.2f× lower, at equal time %.2f× lower (efficiency ratio).\n",
              b.variance / m.variance, (b.relative - floor_relative) / std::max(m.relative - floor_relative, 1e-30),
              b.rel_mse / m.rel_mse, (b.rel_mse * b.seconds) / (m.rel_mse * m.seconds));
  // The median of per-rep variances reads a heavy-tailed pixel low (a 64-spp
  // run rarely holds its rare large samples); all reps' samples together
  // estimate it from reps·spp samples.
  std::printf("Variance per sample from all %d reps' samples together (%d per pixel): MIS %.4g, BSDF only %.4g, %.2f× "
              "lower.\n",
              o.reps, o.reps * o.spp, m.variance_all, b.variance_all, b.variance_all / m.variance_all);
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bench_mis: %s\n", e.what());
  return 2;
}
