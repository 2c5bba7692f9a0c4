// The BVH against brute force (random triangle soups and the generated
// terrain), its structural invariants and SAH quality, watertightness of the
// triangle test, and the analytic shapes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "geometry/Bvh.h"
#include "geometry/Mesh.h"
#include "geometry/Shape.h"
#include "geometry/Surfaces.h"
#include "geometry/Triangle.h"
#include "render/vulkan/SurfacePacking.h"
#include "shared/geometry_types.h"
#include "support/RandomDirections.h"

using namespace pyrolume;
using namespace pyrolume::geometry;

namespace {

const std::filesystem::path kTerrain = std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/terrain/mountain.obj";

using test::random_unit;

// `count` triangles in [−1, 1]³ with sizes from tiny to large, some
// degenerate (zero area), some sharing vertices.
std::vector<Triangle> random_soup(size_t count, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0), size(0.0, 1.0);
  std::vector<Triangle> tris;
  for (size_t i = 0; i < count; ++i) {
    Triangle t;
    const glm::dvec3 c(u(rng), u(rng), u(rng));
    const double s = 0.4 * std::pow(size(rng), 3.0) + 1e-4;
    for (int k = 0; k < 3; ++k) t.p[k] = glm::vec3(c + s * glm::dvec3(u(rng), u(rng), u(rng)));
    if (i % 97 == 5) t.p[2] = t.p[1];                     // degenerate: a segment
    if (i % 89 == 3 && i > 0) t.p[0] = tris[i - 1].p[1];  // shares a vertex
    t.uv = {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(0, 1)};
    t.has_uvs = true;
    t.material = uint32_t(i % 3);
    t.source = uint32_t(i);
    tris.push_back(t);
  }
  return tris;
}

struct Comparison {
  size_t rays = 0, hits = 0, mismatches = 0, ties = 0;
  std::string first;
};

// Closest hit and occluded() of the BVH against brute force over the BVH's own
// triangle order (so ids compare directly).
Comparison compare_with_brute_force(const Bvh& bvh, const std::vector<Ray>& rays, const std::vector<double>& t_max) {
  Comparison c;
  for (size_t i = 0; i < rays.size(); ++i) {
    ++c.rays;
    SurfaceHit a, b;
    const bool ha = intersect(bvh, rays[i], t_max[i], a);
    const bool hb = intersect_brute_force(bvh.triangles, rays[i], t_max[i], b);
    const bool oa = occluded(bvh, rays[i], t_max[i]);
    const bool ob = occluded_brute_force(bvh.triangles, rays[i], t_max[i]);
    bool ok = ha == hb && oa == ob && oa == ha;
    if (ok && ha) {
      ++c.hits;
      ok = std::fabs(a.t - b.t) <= 1e-5 * b.t;
      if (ok && a.primitive != b.primitive) {
        // A tie: both triangles are hit at the same distance (shared edge or
        // coplanar overlap). Anything else is a wrong answer.
        ++c.ties;
        ok = std::fabs(a.t - b.t) <= 1e-12 * b.t;
      }
      if (ok && a.primitive == b.primitive) ok = a.b1 == b.b1 && a.b2 == b.b2 && a.uv == b.uv && a.normal == b.normal;
    }
    if (!ok) {
      if (c.mismatches == 0)
        c.first = "ray " + std::to_string(i) + ": bvh " +
                  (ha ? "t=" + std::to_string(a.t) + " tri " + std::to_string(a.primitive) : "miss") + " occluded " +
                  std::to_string(oa) + " vs brute " +
                  (hb ? "t=" + std::to_string(b.t) + " tri " + std::to_string(b.primitive) : "miss") + " occluded " +
                  std::to_string(ob);
      ++c.mismatches;
    }
  }
  return c;
}

void random_rays(size_t count, uint64_t seed, double extent, std::vector<Ray>& rays, std::vector<double>& t_max) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-extent, extent), unit(0.0, 1.0);
  for (size_t i = 0; i < count; ++i) {
    Ray r;
    r.origin = glm::dvec3(u(rng), u(rng), u(rng));
    if (i % 4 == 0) {
      // Aimed at a random point inside: most such rays hit something.
      r.direction = glm::dvec3(0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng)) - r.origin;
    } else {
      r.direction = random_unit(rng);
    }
    if (i % 16 == 1) r.direction = glm::dvec3(0.0, (i % 32 == 1) ? -1.0 : 1.0, 0.0);  // axis-parallel
    if (i % 16 == 2) r.direction = glm::dvec3(1.0, 0.0, 1e-30);                       // nearly so
    if (i % 8 == 3) r.direction *= 3.7;                                               // not unit length
    rays.push_back(r);
    t_max.push_back(i % 3 == 0 ? unit(rng) * 2.0 * extent : std::numeric_limits<double>::infinity());
  }
}

void check_structure(const Bvh& bvh, size_t triangle_count, uint32_t max_leaf) {
  ASSERT_FALSE(bvh.nodes.empty());
  ASSERT_EQ(bvh.triangles.size(), triangle_count);
  ASSERT_LT(bvh.depth, gpu::BVH_STACK_SIZE);
  std::vector<int> covered(triangle_count, 0);
  std::vector<int> source_seen(triangle_count, 0);
  for (const Triangle& t : bvh.triangles) {
    ASSERT_LT(t.source, triangle_count);
    ++source_seen[t.source];
  }
  for (int s : source_seen) ASSERT_EQ(s, 1) << "a triangle is missing or duplicated";
  // Walk the tree: children inside parents, leaves own disjoint ranges.
  struct Item {
    uint32_t node, depth;
  };
  std::vector<Item> todo = {{0, 0}};
  uint32_t deepest = 0;
  while (!todo.empty()) {
    const Item it = todo.back();
    todo.pop_back();
    const BvhNode& n = bvh.nodes[it.node];
    deepest = std::max(deepest, it.depth);
    if (n.is_leaf()) {
      ASSERT_LE(n.count, max_leaf);
      if (triangle_count > 0) ASSERT_GE(n.count, 1u);
      for (uint32_t i = n.offset; i < n.offset + n.count; ++i) {
        ASSERT_LT(i, triangle_count);
        ++covered[i];
        for (const glm::vec3& p : bvh.triangles[i].p) {
          ASSERT_TRUE(glm::all(glm::greaterThanEqual(p, n.bounds_min)) && glm::all(glm::lessThanEqual(p, n.bounds_max)))
              << "triangle " << i << " sticks out of leaf " << it.node;
        }
      }
    } else {
      ASSERT_LT(n.axis, 3u);
      const uint32_t kids[2] = {it.node + 1, n.offset};
      ASSERT_GT(n.offset, it.node + 1);
      ASSERT_LT(n.offset, bvh.nodes.size());
      for (uint32_t k : kids) {
        const BvhNode& c = bvh.nodes[k];
        ASSERT_TRUE(glm::all(glm::greaterThanEqual(c.bounds_min, n.bounds_min)) &&
                    glm::all(glm::lessThanEqual(c.bounds_max, n.bounds_max)))
            << "child " << k << " outside node " << it.node;
        todo.push_back({k, it.depth + 1});
      }
    }
  }
  EXPECT_EQ(deepest, bvh.depth);
  for (size_t i = 0; i < triangle_count; ++i)
    ASSERT_EQ(covered[i], 1) << "triangle " << i << " in " << covered[i] << " leaves";
}

}  // namespace

TEST(Bvh, ClosestHitAndOcclusionEqualBruteForceOnRandomSoups) {
  for (size_t count : {size_t(1), size_t(2), size_t(5), size_t(64), size_t(1000), size_t(3000)}) {
    SCOPED_TRACE("soup of " + std::to_string(count));
    const Bvh bvh = build_bvh(random_soup(count, 1000 + count));
    check_structure(bvh, count, 4);
    std::vector<Ray> rays;
    std::vector<double> t_max;
    random_rays(3000, 77 + count, 1.6, rays, t_max);
    const Comparison c = compare_with_brute_force(bvh, rays, t_max);
    EXPECT_EQ(c.mismatches, 0u) << c.first;
    if (count >= 1000) EXPECT_GT(c.hits, c.rays / 10) << "too few hits for the test to mean anything";
  }
}

TEST(Bvh, ComparisonDetectsABrokenTree) {
  // The comparison above must be able to fail: shrink one leaf's box so its
  // triangles are culled, and the same check finds wrong answers.
  Bvh bvh = build_bvh(random_soup(1000, 5));
  std::vector<Ray> rays;
  std::vector<double> t_max;
  random_rays(3000, 6, 1.6, rays, t_max);
  size_t broken = 0;
  for (BvhNode& n : bvh.nodes)
    if (n.is_leaf() && broken < 40) {
      n.bounds_max = n.bounds_min;
      ++broken;
    }
  EXPECT_GT(compare_with_brute_force(bvh, rays, t_max).mismatches, 0u);
}

// pack_gpu_nodes folds the leaves into their parents: each GPU node holds its
// two children's boxes exactly as the binary tree has them, interior children
// point at nodes that hold their own children, and every triangle is in
// exactly one leaf child.
TEST(Bvh, GpuNodesHoldBothChildrenAndEveryTriangleOnce) {
  const Bvh bvh = build_bvh(random_soup(3000, 21));
  const std::vector<gpu::GpuBvhNode> g = pack_gpu_nodes(bvh);
  size_t interior = 0;
  for (const BvhNode& n : bvh.nodes) interior += n.is_leaf() ? 0 : 1;
  ASSERT_EQ(g.size(), interior);
  std::vector<int> covered(bvh.triangles.size(), 0);
  // Walk both trees together from their roots.
  std::vector<std::pair<uint32_t, uint32_t>> todo = {{0u, 0u}};  // (binary node, GPU node)
  size_t visited = 0;
  while (!todo.empty()) {
    const auto [b, k] = todo.back();
    todo.pop_back();
    ASSERT_LT(k, g.size());
    ++visited;
    const BvhNode& n = bvh.nodes[b];
    ASSERT_FALSE(n.is_leaf());
    const uint32_t kids[2] = {b + 1, n.offset};
    const uint32_t child[2] = {g[k].child0, g[k].child1}, count[2] = {g[k].count0, g[k].count1};
    for (int j = 0; j < 2; ++j) {
      const BvhNode& c = bvh.nodes[kids[j]];
      EXPECT_EQ(glm::vec3(g[k].x[j], g[k].y[j], g[k].z[j]), c.bounds_min);
      EXPECT_EQ(glm::vec3(g[k].x[2 + j], g[k].y[2 + j], g[k].z[2 + j]), c.bounds_max);
      if (c.is_leaf()) {
        ASSERT_EQ(count[j], c.count);
        for (uint32_t i = 0; i < c.count; ++i) ++covered[child[j] + i];
      } else {
        ASSERT_EQ(count[j], gpu::BVH_INTERIOR_CHILD);
        todo.push_back({kids[j], child[j]});
      }
    }
  }
  EXPECT_EQ(visited, g.size());
  for (size_t i = 0; i < covered.size(); ++i) ASSERT_EQ(covered[i], 1) << "triangle " << i;
}

TEST(Bvh, EmptyAndDegenerateInputs) {
  const Bvh empty = build_bvh({});
  ASSERT_EQ(empty.nodes.size(), 1u);
  EXPECT_TRUE(empty.nodes[0].is_leaf());
  EXPECT_EQ(empty.nodes[0].count, 0u);
  SurfaceHit hit;
  EXPECT_FALSE(intersect(empty, Ray{{0, 0, -1}, {0, 0, 1}}, 1e30, hit));
  EXPECT_FALSE(occluded(empty, Ray{{0, 0, -1}, {0, 0, 1}}, 1e30));

  // 50 copies of one triangle: the centroids coincide, no SAH split exists,
  // still leaves of at most 4.
  Triangle t;
  t.p = {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)};
  std::vector<Triangle> same(50, t);
  for (uint32_t i = 0; i < 50; ++i) same[i].source = i;
  const Bvh bvh = build_bvh(same);
  check_structure(bvh, 50, 4);
  ASSERT_TRUE(intersect(bvh, Ray{{0.2, 0.2, -1}, {0, 0, 1}}, 1e30, hit));
  EXPECT_DOUBLE_EQ(hit.t, 1.0);
}

TEST(Bvh, DepthStaysWithinTheGpuStack) {
  // Each triangle half the size of the last and next to it: SAH peels one off
  // per level (depth ~120) unless the builder caps the depth.
  std::vector<Triangle> tris;
  for (int i = 0; i < 120; ++i) {
    const float s = std::ldexp(1.0f, -i);
    Triangle t;
    t.p = {glm::vec3(s, 0, 0), glm::vec3(1.5f * s, 0, 0), glm::vec3(s, 0.5f * s, 0.1f * s)};
    t.source = uint32_t(i);
    tris.push_back(t);
  }
  const Bvh bvh = build_bvh(tris);
  check_structure(bvh, tris.size(), 4);
  EXPECT_LT(bvh.depth, gpu::BVH_STACK_SIZE);
  std::vector<Ray> rays;
  std::vector<double> t_max;
  std::mt19937_64 rng(3);
  for (int i = 0; i < 2000; ++i) {
    const double x = std::ldexp(1.2, -int(rng() % 120));
    rays.push_back(Ray{{x, 0.1 * x, -1.0}, glm::dvec3(0.0, 0.0, 1.0) + 0.01 * random_unit(rng) * x});
    t_max.push_back(1e30);
  }
  const Comparison c = compare_with_brute_force(bvh, rays, t_max);
  EXPECT_EQ(c.mismatches, 0u) << c.first;
  EXPECT_GT(c.hits, 100u);
}

TEST(Bvh, SahCostBeatsMedianSplitsAndBruteForce) {
  // Clustered soup: SAH's advantage over object-median splits shows where
  // triangle density varies.
  std::vector<Triangle> tris = random_soup(2000, 11);
  for (size_t i = 0; i < tris.size(); i += 2)
    for (glm::vec3& p : tris[i].p) p = 0.1f * p + glm::vec3(0.7f);
  const Bvh sah = build_bvh(tris);
  BvhOptions median_opt;
  median_opt.split = BvhSplit::Median;
  const Bvh median = build_bvh(tris, median_opt);
  check_structure(sah, tris.size(), 4);
  check_structure(median, tris.size(), 4);
  const double c_sah = sah_cost(sah), c_median = sah_cost(median);
  EXPECT_LT(c_sah, c_median) << "SAH " << c_sah << " vs median " << c_median;
  EXPECT_LT(c_sah, 0.05 * double(tris.size())) << "no better than testing every triangle";
  // A single leaf costs its count: three copies of one triangle cannot split.
  std::vector<Triangle> three(3, tris[0]);
  for (uint32_t i = 0; i < 3; ++i) three[i].source = i;
  const Bvh leaf = build_bvh(three);
  ASSERT_EQ(leaf.nodes.size(), 1u);
  EXPECT_DOUBLE_EQ(sah_cost(leaf), 3.0);
  // Mapping of the cost: 1 interior + two children.
  Triangle a, b;
  a.p = {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)};
  b.p = {glm::vec3(9, 0, 0), glm::vec3(10, 0, 0), glm::vec3(9, 1, 0)};
  BvhOptions one;
  one.max_leaf_size = 1;
  const Bvh two = build_bvh({a, b}, one);
  ASSERT_EQ(two.nodes.size(), 3u);
  // Boxes are flat (z extent 0): area = 2·x·y. Root 10×1, leaves 1×1.
  EXPECT_NEAR(sah_cost(two), 1.0 + 2.0 * (2.0 / 20.0), 1e-12);
}

TEST(Bvh, TerrainClosestHitsEqualBruteForce) {
  const Mesh mesh = load_obj(kTerrain);
  const Bvh bvh = build_bvh(triangles_of(mesh, 0, 0));
  check_structure(bvh, mesh.triangles.size(), 4);
  std::vector<Ray> rays;
  std::vector<double> t_max;
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(-12.0, 12.0), h(0.0, 8.0);
  for (int i = 0; i < 2000; ++i) {
    Ray r;
    r.origin = glm::dvec3(u(rng), h(rng) + (i % 2 ? 6.0 : 0.0), u(rng));
    const glm::dvec3 target(0.6 * u(rng), 0.3 * h(rng), 0.6 * u(rng));
    r.direction = i % 5 == 0 ? random_unit(rng) : target - r.origin;
    rays.push_back(r);
    t_max.push_back(i % 4 == 0 ? 0.7 : 1e30);  // short shadow-like segments too
  }
  const Comparison c = compare_with_brute_force(bvh, rays, t_max);
  EXPECT_EQ(c.mismatches, 0u) << c.first;
  EXPECT_GT(c.hits, 1000u);
}

TEST(Bvh, TerrainIsWatertightAtVerticesAndEdges) {
  // Rays straight down through exact grid vertices and edge midpoints must
  // hit: a crack between triangles would let them through.
  const Mesh mesh = load_obj(kTerrain);
  const Bvh bvh = build_bvh(triangles_of(mesh, 0, 0));
  size_t rays = 0, misses = 0;
  for (size_t i = 0; i < mesh.positions.size(); i += 3) {
    const glm::dvec3 p(mesh.positions[i]);
    if (std::fabs(p.x) >= 9.999 || std::fabs(p.z) >= 9.999) continue;  // the rim: nothing beyond
    for (const glm::dvec3& o :
         {p, p + glm::dvec3(0.125, 0, 0), p + glm::dvec3(0, 0, 0.125), p + glm::dvec3(0.125, 0, 0.125)}) {
      SurfaceHit hit;
      ++rays;
      if (!intersect(bvh, Ray{{o.x, 50.0, o.z}, {0.0, -1.0, 0.0}}, 1e30, hit)) ++misses;
      // Tilted rays through the same point (edges shared at an angle).
      const glm::dvec3 slant(20.0, 40.0, 7.0);
      if (!intersect(bvh, Ray{o + slant, -slant}, 1e30, hit)) ++misses;
    }
  }
  EXPECT_GT(rays, 1000u);
  EXPECT_EQ(misses, 0u) << "rays slipped through the mesh";
}

TEST(Bvh, OffsetOriginAvoidsSelfIntersection) {
  const Mesh mesh = load_obj(kTerrain);
  const Bvh bvh = build_bvh(triangles_of(mesh, 0, 0));
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-8.0, 8.0);
  size_t tested = 0, self = 0;
  for (int i = 0; i < 2000; ++i) {
    SurfaceHit hit;
    const Ray r{{u(rng), 30.0, u(rng)}, glm::dvec3(0.3 * u(rng), -30.0, 0.3 * u(rng))};
    if (!intersect(bvh, r, 1e30, hit)) continue;
    glm::dvec3 n = glm::dot(hit.normal, r.direction) < 0.0 ? hit.normal : -hit.normal;
    glm::dvec3 d = random_unit(rng);
    if (glm::dot(d, n) < 0.0) d = -d;  // leave on the side the ray came from
    const Ray next{offset_ray_origin(hit.position, n), d};
    SurfaceHit h2;
    ++tested;
    if (intersect(bvh, next, 1e30, h2) && h2.primitive == hit.primitive) ++self;
  }
  EXPECT_GT(tested, 1000u);
  EXPECT_EQ(self, 0u);
}

TEST(Shapes, SphereHitsUvAndInside) {
  const SurfaceShape s = make_sphere({1, 2, 3}, 2.0, 7);
  SurfaceHit hit;
  // From −z toward the centre: enters at z = 1, the sphere's −z pole on the equator.
  ASSERT_TRUE(intersect_shape(s, Ray{{1, 2, -5}, {0, 0, 2}}, 1e30, hit));
  EXPECT_NEAR(hit.t, 3.0, 1e-12);  // |d| = 2: t in units of |d|
  EXPECT_NEAR(hit.normal.z, -1.0, 1e-12);
  EXPECT_EQ(hit.material, 7u);
  EXPECT_EQ(hit.kind, HitKind::Shape);
  EXPECT_NEAR(hit.uv.x, 0.75, 1e-12);  // atan2(−1, 0) = −π/2 → 3/4
  EXPECT_NEAR(hit.uv.y, 0.5, 1e-12);
  // From inside: the far side.
  ASSERT_TRUE(intersect_shape(s, Ray{{1, 2, 3}, {0, 1, 0}}, 1e30, hit));
  EXPECT_NEAR(hit.t, 2.0, 1e-12);
  EXPECT_NEAR(hit.uv.y, 1.0, 1e-12);  // north pole
  // t_max cuts it off; missing rays miss.
  EXPECT_FALSE(intersect_shape(s, Ray{{1, 2, -5}, {0, 0, 1}}, 5.9, hit));
  EXPECT_FALSE(intersect_shape(s, Ray{{1, 4.001, -5}, {0, 0, 1}}, 1e30, hit));
  EXPECT_FALSE(intersect_shape(s, Ray{{1, 2, 6}, {0, 0, 1}}, 1e30, hit));  // behind
  // A far sphere keeps its precision (the stable quadratic).
  const SurfaceShape far = make_sphere({0, 0, 1e6}, 1.0, 0);
  ASSERT_TRUE(intersect_shape(far, Ray{{0, 0, 0}, {0, 0, 1}}, 1e30, hit));
  EXPECT_NEAR(hit.t, 1e6 - 1.0, 1e-6);
}

TEST(Shapes, FiniteAndInfinitePlanes) {
  // A 4 × 2 rectangle in the y = 1 plane, u along +x, v = cross(n, u) = −z.
  const SurfaceShape rect = make_plane({0, 1, 0}, {0, 2, 0}, {1, 0.5, 0}, 4.0, 2.0, 3);
  EXPECT_NEAR(glm::length(rect.normal), 1.0, 1e-15);
  EXPECT_NEAR(glm::dot(rect.u_axis, glm::dvec3(1, 0, 0)), 1.0, 1e-15);
  SurfaceHit hit;
  ASSERT_TRUE(intersect_shape(rect, Ray{{1.5, 5, -0.5}, {0, -1, 0}}, 1e30, hit));
  EXPECT_NEAR(hit.t, 4.0, 1e-12);
  EXPECT_NEAR(hit.uv.x, 1.5 / 4.0 + 0.5, 1e-12);
  EXPECT_NEAR(hit.uv.y, 0.5 / 2.0 + 0.5, 1e-12);  // z = −0.5 is +0.5 along v = −z
  EXPECT_EQ(hit.material, 3u);
  // From below: two-sided, same normal (not flipped).
  ASSERT_TRUE(intersect_shape(rect, Ray{{0, -1, 0}, {0, 1, 0}}, 1e30, hit));
  EXPECT_NEAR(hit.normal.y, 1.0, 1e-15);
  EXPECT_FALSE(intersect_shape(rect, Ray{{2.01, 5, 0}, {0, -1, 0}}, 1e30, hit));
  EXPECT_FALSE(intersect_shape(rect, Ray{{0, 5, 1.01}, {0, -1, 0}}, 1e30, hit));
  EXPECT_FALSE(intersect_shape(rect, Ray{{0, 5, 0}, {1, 0, 0}}, 1e30, hit));  // parallel
  const SurfaceShape ground = make_plane({0, 0, 0}, {0, 1, 0}, {1, 0, 0}, 0.0, 0.0, 0);
  ASSERT_TRUE(intersect_shape(ground, Ray{{1e4, 1, 3e4}, {0.001, -1, 0}}, 1e30, hit));
  EXPECT_NEAR(hit.uv.x, 1e4 + 0.001, 1e-6);  // one repeat per unit
}

TEST(Surfaces, ClosestOfTrianglesAndShapesAndAlbedo) {
  Surfaces s;
  Triangle t;
  t.p = {glm::vec3(-1, -1, 2), glm::vec3(1, -1, 2), glm::vec3(-1, 1, 2)};
  t.uv = {glm::vec2(0, 0), glm::vec2(1, 0), glm::vec2(0, 1)};
  t.has_uvs = true;
  t.material = 1;
  s.bvh = build_bvh({t});
  s.shapes.push_back(make_sphere({0, 0, 5}, 1.0, 0));
  s.materials = {Material{glm::dvec3(0.2, 0.3, 0.4), -1}, Material{glm::dvec3(1.0), 0}};
  s.textures.push_back(Texture(1, 1, {0.5f, 0.25f, 0.125f}));
  SurfaceHit hit;
  ASSERT_TRUE(intersect(s, Ray{{-0.5, -0.5, 0}, {0, 0, 1}}, 1e30, hit));
  EXPECT_EQ(hit.kind, HitKind::Triangle);
  EXPECT_NEAR(hit.t, 2.0, 1e-12);
  EXPECT_NEAR(hit.uv.x, 0.25, 1e-12);
  EXPECT_NEAR(hit.uv.y, 0.25, 1e-12);
  EXPECT_NEAR(albedo_at(s, hit).g, 0.25, 1e-7);
  ASSERT_TRUE(intersect(s, Ray{{0.5, 0.5, 0}, {0, 0, 1}}, 1e30, hit));  // beside the triangle
  EXPECT_EQ(hit.kind, HitKind::Shape);
  EXPECT_NEAR(hit.t, 5.0 - std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(albedo_at(s, hit).b, 0.4, 1e-12);
  EXPECT_TRUE(occluded(s, Ray{{0.5, 0.5, 0}, {0, 0, 1}}, 5.0));
  EXPECT_FALSE(occluded(s, Ray{{0.5, 0.5, 0}, {0, 0, 1}}, 4.0));

  const GpuSurfaces g = pack_gpu_surfaces(s);
  ASSERT_EQ(g.nodes.size(), 1u);  // the single leaf as the root's child 0, an empty leaf as child 1
  const auto children = [](const gpu::GpuBvhNode& n) { return glm::uvec4(n.child0, n.child1, n.count0, n.count1); };
  EXPECT_EQ(children(g.nodes[0]), glm::uvec4(0u, 0u, 1u, 0u));
  EXPECT_EQ(g.shape_count, 1u);
  EXPECT_EQ(g.shapes[0].kind, gpu::SURFACE_SPHERE);
  EXPECT_EQ(g.attributes[0].material, 1u);
  EXPECT_EQ(g.attributes[0].flags, gpu::TRIANGLE_HAS_UVS);
  EXPECT_EQ(g.materials[0].texture_slot, gpu::NO_TEXTURE);
  EXPECT_EQ(g.materials[1].texture_slot, 0u);
  const GpuSurfaces none = pack_gpu_surfaces(Surfaces{});
  EXPECT_EQ(none.nodes.size(), 1u);
  EXPECT_EQ(children(none.nodes[0]), glm::uvec4(0u, 0u, 0u, 0u));  // two empty leaves
  EXPECT_EQ(none.triangles.size(), 1u);  // a dummy: Vulkan buffers cannot be empty
  EXPECT_EQ(none.triangle_count, 0u);
  EXPECT_EQ(none.shape_count, 0u);
  EXPECT_EQ(none.shapes.size(), 1u);
}
