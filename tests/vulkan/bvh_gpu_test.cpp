// shaders/bvh.glsl (through shaders/test_bvh.comp) against the CPU traversal in
// host/geometry/: the same BVH, triangles and shapes, random rays; closest hits
// (t, primitive, normal, uv, material) and shadow queries must agree up to
// float-vs-double rounding, under the validation layers.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "geometry/Bvh.h"
#include "geometry/Mesh.h"
#include "geometry/Surfaces.h"
#include "render/vulkan/Context.h"
#include "render/vulkan/Memory.h"
#include "render/vulkan/SurfacePacking.h"
#include "shared/geometry_types.h"
#include "support/GpuCompute.h"
#include "support/RandomDirections.h"

using namespace pyrolume;
using namespace pyrolume::geometry;
using namespace pyrolume::vk;

namespace {

// Mirrors of test_bvh.comp's TestRay / TestResult (test-only structs).
struct TestRay {
  glm::vec4 origin;  // xyz; w: t_max
  glm::vec4 direction;
};
struct TestResult {
  glm::vec4 hit;  // t, b1, b2, occluded
  glm::uvec4 id;  // 1 + kind (0 miss), primitive, material
  glm::vec4 normal;
  glm::vec4 shading;
  glm::vec4 uv;  // uv, offset origin xy
};
static_assert(sizeof(TestResult) == 80);

using test::random_unit;

// The terrain, a soup of random triangles floating above it, a sphere, a
// finite rectangle and an infinite ground plane below everything.
Surfaces test_scene() {
  Surfaces s;
  const Mesh terrain = load_obj(std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/terrain/mountain.obj");
  std::vector<Triangle> tris = triangles_of(terrain, 1, 0);
  std::mt19937_64 rng(99);
  std::uniform_real_distribution<double> u(-1.0, 1.0), size(0.0, 1.0);
  for (uint32_t i = 0; i < 2000; ++i) {
    Triangle t;
    const glm::dvec3 c(6.0 * u(rng), 7.0 + 2.0 * u(rng), 6.0 * u(rng));
    const double sz = 0.8 * std::pow(size(rng), 2.0) + 0.01;
    for (int k = 0; k < 3; ++k) t.p[k] = glm::vec3(c + sz * glm::dvec3(u(rng), u(rng), u(rng)));
    t.material = 2;
    t.mesh = 1;
    t.source = uint32_t(tris.size());
    tris.push_back(t);
  }
  s.bvh = build_bvh(std::move(tris));
  s.shapes.push_back(make_sphere({3.0, 6.0, -2.0}, 1.5, 3));
  s.shapes.push_back(make_plane({-4.0, 4.0, 4.0}, {0.3, 1.0, -0.2}, {1, 0, 0}, 4.0, 3.0, 4));
  s.shapes.push_back(make_plane({0.0, -0.5, 0.0}, {0, 1, 0}, {1, 0, 0}, 0.0, 0.0, 5));
  s.materials.resize(6);
  return s;
}

std::vector<geometry::Ray> test_rays(size_t count, std::vector<double>& t_max) {
  std::mt19937_64 rng(1234);
  std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
  std::vector<geometry::Ray> rays;
  for (size_t i = 0; i < count; ++i) {
    geometry::Ray r;
    r.origin = glm::dvec3(14.0 * u(rng), 4.0 + 8.0 * u(rng), 14.0 * u(rng));
    const glm::dvec3 target(8.0 * u(rng), 3.0 + 4.0 * u(rng), 8.0 * u(rng));
    r.direction = i % 3 == 0 ? random_unit(rng) : glm::normalize(target - r.origin);
    if (i % 50 == 7) r.direction = glm::dvec3(0.0, -1.0, 0.0);  // axis-parallel
    if (i % 5 == 1) r.direction *= 2.5;                         // not unit length
    // Round to float first: the GPU gets exactly these numbers.
    r.origin = glm::dvec3(glm::vec3(r.origin));
    r.direction = glm::dvec3(glm::vec3(r.direction));
    rays.push_back(r);
    t_max.push_back(i % 4 == 0 ? double(float(unit(rng) * 20.0)) : 1e30);
  }
  return rays;
}

double min_bary(double b1, double b2) { return std::min(std::min(b1, b2), 1.0 - b1 - b2); }

// test_bvh.comp's answers for `rays` through the packed surfaces `g`, whose
// buffers are of memory `kind` with `usage`; `shape_count` specializes
// SURFACE_SHAPE_COUNT (SURFACE_HAS_TRIANGLES is true).
std::vector<TestResult> trace_on_gpu(Context& ctx, const GpuSurfaces& g, const std::vector<TestRay>& rays,
                                     MemoryKind kind, VkBufferUsageFlags usage, uint32_t shape_count,
                                     const char* name) {
  Buffer nodes = test::filled_buffer(ctx, g.nodes, "bvh nodes", kind, usage);
  Buffer tris = test::filled_buffer(ctx, g.triangles, "bvh triangles", kind, usage);
  Buffer attrs = test::filled_buffer(ctx, g.attributes, "bvh attributes", kind, usage);
  Buffer shapes = test::filled_buffer(ctx, g.shapes, "surface shapes", kind, usage);
  Buffer ray_buf = test::filled_buffer(ctx, rays, "test rays", kind, usage);
  Buffer results(ctx, rays.size() * sizeof(TestResult), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, MemoryKind::Readback,
                 "test results");
  test::run_compute(ctx, "test_bvh.comp", {{&nodes}, {&tris}, {&attrs}, {&shapes}, {&ray_buf}, {&results}},
                    uint32_t(rays.size()), {{0, shape_count}, {1, 1u}}, name);
  std::vector<TestResult> got(rays.size());
  test::read_back(results, got);
  return got;
}

}  // namespace

TEST(BvhGpu, ClosestHitsAndShadowRaysMatchTheCpu) {
  const uint64_t before = Context::total_validation_messages();
  {
    Context ctx(test::validated());
    const Surfaces scene = test_scene();
    ASSERT_LT(scene.bvh.depth, gpu::BVH_STACK_SIZE);
    const GpuSurfaces g = pack_gpu_surfaces(scene);
    std::vector<double> t_max;
    const std::vector<geometry::Ray> rays = test_rays(20000, t_max);
    std::vector<TestRay> gpu_rays(rays.size());
    for (size_t i = 0; i < rays.size(); ++i) {
      gpu_rays[i].origin = glm::vec4(glm::vec3(rays[i].origin), float(t_max[i]));
      gpu_rays[i].direction = glm::vec4(glm::vec3(rays[i].direction), 0.0f);
    }
    const std::vector<TestResult> got =
        trace_on_gpu(ctx, g, gpu_rays, MemoryKind::DeviceLocal,
                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT, g.shape_count, "test_bvh");

    size_t hits = 0, triangle_hits = 0, shape_hits = 0, explained = 0, wrong = 0, shadow_explained = 0;
    std::ostringstream first;
    for (size_t i = 0; i < rays.size(); ++i) {
      SurfaceHit cpu;
      const bool ch = intersect(scene, rays[i], t_max[i], cpu);
      const bool co = occluded(scene, rays[i], t_max[i]);
      const TestResult& r = got[i];
      const bool gh = r.id.x != 0u;
      const double gt = r.hit.x;
      const double len = glm::length(rays[i].direction);
      // Float-vs-double: t agrees to ~1e-5 relative at these distances; a
      // different answer is legitimate only where the two can round apart:
      // a hit within 1e-4 of a triangle edge, a t within 1e-4 of t_max or of
      // the other candidate's t, or a grazing ray.
      const double tol = 2e-5 * std::max(1.0, std::max(gt, cpu.t) * len) / len;
      auto near_edge_gpu = [&] {
        return r.id.x == 1u + uint32_t(HitKind::Triangle) && min_bary(r.hit.y, r.hit.z) < 1e-4;
      };
      auto near_edge_cpu = [&] { return ch && cpu.kind == HitKind::Triangle && min_bary(cpu.b1, cpu.b2) < 1e-4; };
      auto grazing = [&] { return ch && std::fabs(glm::dot(cpu.normal, rays[i].direction)) < 1e-3 * len; };
      auto near_tmax = [&](double t) { return std::fabs(t - t_max[i]) <= tol; };
      bool ok = true, excuse = false;
      if (ch != gh) {
        ok = false;
        excuse = near_edge_gpu() || near_edge_cpu() || grazing() || (ch && near_tmax(cpu.t)) || (gh && near_tmax(gt));
      } else if (ch) {
        ++hits;
        const bool same = r.id.x == 1u + uint32_t(cpu.kind) && r.id.y == cpu.primitive;
        if (cpu.kind == HitKind::Triangle)
          ++triangle_hits;
        else
          ++shape_hits;
        if (same) {
          ok = std::fabs(gt - cpu.t) <= tol && r.id.z == cpu.material &&
               glm::length(glm::dvec3(r.normal) - cpu.normal) < 1e-4 &&
               glm::length(glm::dvec3(r.shading) - cpu.shading_normal) < 1e-3 &&
               glm::length(glm::dvec2(r.uv) - cpu.uv) < 1e-3 * std::max(1.0, glm::length(cpu.uv));
        } else {
          ok = false;
          excuse = std::fabs(gt - cpu.t) <= tol || near_edge_gpu() || near_edge_cpu() || grazing();
        }
      }
      const bool go = r.hit.w != 0.0f;
      if (ok && go != co) {
        ok = false;
        // The shadow query's answer may round apart only like the hits do.
        excuse = near_edge_cpu() || near_edge_gpu() || grazing() || (ch && near_tmax(cpu.t));
        if (excuse) ++shadow_explained;
      }
      if (!ok) {
        if (excuse) {
          ++explained;
        } else {
          if (wrong == 0)
            first << "ray " << i << ": cpu "
                  << (ch ? "t=" + std::to_string(cpu.t) + " kind " + std::to_string(int(cpu.kind)) + " prim " +
                               std::to_string(cpu.primitive)
                         : std::string("miss"))
                  << " occluded " << co << "; gpu " << (gh ? "t=" + std::to_string(gt) : std::string("miss")) << " id "
                  << r.id.x << "/" << r.id.y << " occluded " << go;
          ++wrong;
        }
      }
    }
    EXPECT_EQ(wrong, 0u) << first.str();
    EXPECT_LE(explained, rays.size() / 200) << "too many near-edge disagreements";
    EXPECT_GT(triangle_hits, rays.size() / 3);
    EXPECT_GT(shape_hits, rays.size() / 50);
    std::printf(
        "bvh_gpu: %zu rays, %zu hits (%zu triangle, %zu shape), %zu near-edge/grazing disagreements "
        "(%zu shadow), BVH %zu nodes depth %u\n",
        rays.size(), hits, triangle_hits, shape_hits, explained, shadow_explained, scene.bvh.nodes.size(),
        scene.bvh.depth);
    EXPECT_EQ(ctx.validation_messages(), 0u);
  }
  EXPECT_EQ(Context::total_validation_messages(), before) << "validation messages while destroying the context";
}

TEST(BvhGpu, EmptySceneMissesEverything) {
  const uint64_t before = Context::total_validation_messages();
  {
    Context ctx(test::validated());
    const GpuSurfaces g = pack_gpu_surfaces(Surfaces{});
    std::vector<TestRay> rays(64);
    for (size_t i = 0; i < rays.size(); ++i) {
      rays[i].origin = glm::vec4(0.0f, 0.0f, 0.0f, 1e30f);
      rays[i].direction = glm::vec4(std::cos(0.1f * float(i)), 0.3f, std::sin(0.1f * float(i)), 0.0f);
    }
    // The empty BVH is traversed (SURFACE_HAS_TRIANGLES = true): its one leaf
    // holds nothing.
    const std::vector<TestResult> r = trace_on_gpu(ctx, g, rays, MemoryKind::HostVisible,
                                                   VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 0u, "test_bvh empty");
    const uint32_t count = uint32_t(rays.size());
    for (uint32_t i = 0; i < count; ++i) {
      EXPECT_EQ(r[i].id.x, 0u) << i;
      EXPECT_EQ(r[i].hit.w, 0.0f) << i;
    }
    EXPECT_EQ(ctx.validation_messages(), 0u);
  }
  EXPECT_EQ(Context::total_validation_messages(), before);
}
