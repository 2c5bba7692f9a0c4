// bench_lookup: the bare density-lookup loop on the Vulkan device, the ceiling
// for the renderer's density lookups per second (issue 21; docs/benchmarks.md).
//
//   bench_lookup [--size N] [--invocations W] [--steps S] [--reps R] [--device I]
//
// A N³ R16F noise volume (values in [0.5, 1), sampled trilinearly, as the
// renderer samples its density textures) and W×W invocations, each a random
// walk of S dependent lookups (shaders/bench_lookup.comp). Prints one line per
// repetition and the median, in M lookups/s; with --json, one JSON object
// {"lookups_per_second": median, "runs": [...]} on stdout instead.
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "render/vulkan/Context.h"
#include "render/vulkan/Memory.h"
#include "render/vulkan/Pipeline.h"
#include "render/vulkan/Spirv.h"
#include "util/Error.h"

using namespace pyrolume;

namespace {

struct Options {
  uint32_t size = 256, invocations = 512, steps = 256, reps = 3;
  int device = -1;
  bool json = false;
};

const char* kUsage =
    "usage: bench_lookup [--size N] [--invocations W] [--steps S] [--reps R] [--device I] [--json]\n"
    "  The bare density-lookup loop: W x W invocations (default 512), each a random walk of S\n"
    "  (default 256) dependent trilinear lookups in an N^3 (default 256) R16F noise volume.\n"
    "  Prints M lookups/s per repetition (default 3) and their median; --json prints\n"
    "  {\"lookups_per_second\": median, \"runs\": [...]} instead.\n";

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto number = [&](uint32_t lo, uint32_t hi) {
      if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
      const std::string v = argv[++i];
      size_t used = 0;
      unsigned long n = 0;
      try {
        n = std::stoul(v, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != v.size() || n < lo || n > hi)
        throw std::invalid_argument(a + " " + v + ": expected an integer in [" + std::to_string(lo) + ", " +
                                    std::to_string(hi) + "]");
      return uint32_t(n);
    };
    if (a == "-h" || a == "--help") {
      std::fputs(kUsage, stdout);
      std::exit(0);
    } else if (a == "--size") {
      o.size = number(2, 1024);
    } else if (a == "--invocations") {
      o.invocations = number(8, 4096);
    } else if (a == "--steps") {
      o.steps = number(1, 1u << 20);
    } else if (a == "--reps") {
      o.reps = number(1, 100);
    } else if (a == "--device") {
      o.device = int(number(0, 64));
    } else if (a == "--json") {
      o.json = true;
    } else {
      throw std::invalid_argument("unknown argument " + a);
    }
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  try {
    o = parse(argc, argv);
  } catch (const std::invalid_argument& e) {
    std::fprintf(stderr, "bench_lookup: %s\n%s", e.what(), kUsage);
    return 2;
  }
  try {
    vk::Context::Options co;
    co.device_index = o.device;
    vk::Context ctx(co);
    // Noise texels: half floats in [0.5, 1) (exponent of 0.5, a random mantissa).
    const size_t n = size_t(o.size) * o.size * o.size;
    std::vector<uint16_t> texels(n);
    uint32_t state = 12345u;
    for (uint16_t& t : texels) {
      state = state * 1664525u + 1013904223u;
      t = uint16_t(0x3800u | ((state >> 16) & 0x3FFu));
    }
    vk::Image3D noise(ctx, o.size, o.size, o.size, VK_FORMAT_R16_SFLOAT, "bench noise");
    noise.upload(ctx, texels.data(), texels.size() * sizeof(uint16_t));
    const uint32_t w = (o.invocations + 7) / 8 * 8;
    vk::Buffer sums(ctx, VkDeviceSize(w) * w * sizeof(float), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                    vk::MemoryKind::Readback, "bench sums");
    struct Push {
      uint32_t width, steps, seed;
      float step_texels;
    };
    vk::ComputePipeline pipeline(ctx, vk::load_spirv("bench_lookup.comp"),
                                 {{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER}, {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER}},
                                 sizeof(Push), {}, "bench_lookup");
    vk::DescriptorSet set(ctx, pipeline);
    set.write_image(0, noise);
    set.write_buffer(1, sums);
    auto run = [&](uint32_t seed, uint32_t steps) {
      const Push push{w, steps, seed, 1.0f};
      const auto t0 = std::chrono::steady_clock::now();
      vk::submit_and_wait(ctx, [&](VkCommandBuffer cmd) {
        pipeline.bind(cmd, set.set());
        pipeline.push(cmd, &push, sizeof push);
        vkCmdDispatch(cmd, w / 8, w / 8, 1);
        vk::to_host_read_barrier(cmd);
      });
      return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    };
    run(0, 1);  // the pipeline's first dispatch compiles it
    std::vector<double> rates;
    for (uint32_t r = 0; r < o.reps; ++r) {
      const double seconds = run(r + 1, o.steps);
      rates.push_back(double(w) * w * o.steps / seconds);
      if (!o.json)
        std::printf("run %u: %.3f s, %.1f M lookups/s\n", r + 1, seconds, rates.back() / 1e6);
    }
    std::vector<double> sorted = rates;
    std::sort(sorted.begin(), sorted.end());
    const double median = sorted[sorted.size() / 2];
    if (o.json) {
      std::printf("{\"device\": \"%s\", \"lookups_per_second\": %.6g, \"runs\": [", ctx.info().name.c_str(), median);
      for (size_t i = 0; i < rates.size(); ++i) std::printf("%s%.6g", i ? ", " : "", rates[i]);
      std::printf("]}\n");
    } else {
      std::printf("median: %.1f M lookups/s (%s, %ux%u invocations x %u steps, %u^3 R16F)\n", median / 1e6,
                  ctx.info().name.c_str(), w, w, o.steps, o.size);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_lookup: %s\n", e.what());
    return 1;
  }
  return 0;
}
