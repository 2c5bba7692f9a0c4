#include "geometry/Bvh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <tuple>


namespace pyrolume::geometry {
namespace {

struct Box {
  glm::vec3 lo{std::numeric_limits<float>::infinity()};
  glm::vec3 hi{-std::numeric_limits<float>::infinity()};
  void grow(const glm::vec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Box& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return lo.x > hi.x; }
  double area() const {
    if (empty()) return 0.0;
    const glm::dvec3 e = glm::dvec3(hi) - glm::dvec3(lo);
    return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
};

struct PrimInfo {
  Box box;
  glm::vec3 centroid;
};

double node_area(const BvhNode& n) {
  const glm::dvec3 e = glm::dvec3(n.bounds_max) - glm::dvec3(n.bounds_min);
  return 2.0 * (e.x * e.y + e.y * e.z + e.z * e.x);
}

class Builder {
 public:
  Builder(const std::vector<Triangle>& tris, const BvhOptions& opt) : opt_(opt) {
    if (opt_.max_leaf_size < 1 || opt_.max_leaf_size > kBvhMaxLeafTriangles)
      throw std::invalid_argument("BvhOptions::max_leaf_size must be 1.." +
                                  std::to_string(kBvhMaxLeafTriangles));
    if (opt_.bins < 2) throw std::invalid_argument("BvhOptions::bins must be at least 2");
    info_.resize(tris.size());
    index_.resize(tris.size());
    for (size_t i = 0; i < tris.size(); ++i) {
      for (const glm::vec3& p : tris[i].p) info_[i].box.grow(p);
      info_[i].centroid = 0.5f * (info_[i].box.lo + info_[i].box.hi);
      index_[i] = uint32_t(i);
    }
  }

  void run(Bvh& bvh) {
    if (index_.empty()) {  // the empty BVH: one leaf without triangles
      BvhNode leaf;
      leaf.axis = BvhNode::kLeaf;
      nodes_.push_back(leaf);
    } else {
      build(0, uint32_t(index_.size()), 0);
    }
    bvh.nodes = std::move(nodes_);
    bvh.depth = depth_;
  }

  const std::vector<uint32_t>& order() const { return index_; }

 private:
  // Most triangles a subtree rooted at `depth` can hold when every leaf stays
  // at depth ≤ kMaxDepth.
  double capacity(uint32_t depth) const {
    return double(opt_.max_leaf_size) * std::ldexp(1.0, int(kMaxDepth) - int(depth));
  }

  uint32_t build(uint32_t begin, uint32_t end, uint32_t depth) {
    const uint32_t node = uint32_t(nodes_.size());
    nodes_.emplace_back();
    depth_ = std::max(depth_, depth);
    Box bounds, cbounds;
    for (uint32_t i = begin; i < end; ++i) {
      bounds.grow(info_[index_[i]].box);
      cbounds.grow(info_[index_[i]].centroid);
    }
    nodes_[node].bounds_min = bounds.lo;
    nodes_[node].bounds_max = bounds.hi;
    const uint32_t n = end - begin;
    auto make_leaf = [&] {
      nodes_[node].offset = begin;
      nodes_[node].count = n;
      nodes_[node].axis = BvhNode::kLeaf;
      return node;
    };
    // Depth kMaxDepth only ever holds ≤ max_leaf_size triangles (capacity()).
    if (n == 1 || depth >= kMaxDepth) return make_leaf();

    uint32_t mid = begin;
    int axis = -1;
    if (opt_.split == BvhSplit::Sah) {
      auto [sah_axis, sah_mid, leaf_better] = split_sah(begin, end, bounds, cbounds);
      if (leaf_better && n <= opt_.max_leaf_size) return make_leaf();
      if (sah_axis >= 0 && double(std::max(sah_mid - begin, end - sah_mid)) <= capacity(depth + 1)) {
        axis = sah_axis;
        mid = sah_mid;
      }
    } else if (n <= opt_.max_leaf_size) {
      return make_leaf();
    }
    if (axis < 0) std::tie(axis, mid) = split_median(begin, end, cbounds);

    nodes_[node].axis = uint32_t(axis);
    build(begin, mid, depth + 1);
    const uint32_t second = build(mid, end, depth + 1);
    nodes_[node].offset = second;
    return node;
  }

  // Returns (axis, mid, leaf_is_cheaper); axis −1 when the centroids coincide.
  std::tuple<int, uint32_t, bool> split_sah(uint32_t begin, uint32_t end, const Box& bounds, const Box& cbounds) {
    const uint32_t n = end - begin;
    const int nb = opt_.bins;
    const double area = bounds.area();
    double best_cost = std::numeric_limits<double>::infinity();
    int best_axis = -1, best_bin = 0;
    std::vector<Box> bin_box(static_cast<size_t>(nb));
    std::vector<uint32_t> bin_count(static_cast<size_t>(nb));
    std::vector<double> right_area(static_cast<size_t>(nb));
    std::vector<uint32_t> right_count(static_cast<size_t>(nb));
    for (int a = 0; a < 3; ++a) {
      const float lo = cbounds.lo[a], hi = cbounds.hi[a];
      if (!(hi > lo)) continue;
      std::fill(bin_box.begin(), bin_box.end(), Box{});
      std::fill(bin_count.begin(), bin_count.end(), 0u);
      for (uint32_t i = begin; i < end; ++i) {
        const int b = bin_of(info_[index_[i]].centroid[a], lo, hi);
        bin_box[size_t(b)].grow(info_[index_[i]].box);
        ++bin_count[size_t(b)];
      }
      // Sweep from the right, then from the left: cost of splitting after bin s
      // = C_trav + (N_L·A_L + N_R·A_R)/A (C_trav = C_isect = 1).
      Box acc;
      uint32_t cnt = 0;
      for (int s = nb - 1; s > 0; --s) {
        acc.grow(bin_box[size_t(s)]);
        cnt += bin_count[size_t(s)];
        right_area[size_t(s)] = acc.area();
        right_count[size_t(s)] = cnt;
      }
      acc = Box{};
      cnt = 0;
      for (int s = 0; s < nb - 1; ++s) {
        acc.grow(bin_box[size_t(s)]);
        cnt += bin_count[size_t(s)];
        const uint32_t rc = right_count[size_t(s + 1)];
        if (cnt == 0 || rc == 0) continue;
        const double cost =
            1.0 + (double(cnt) * acc.area() + double(rc) * right_area[size_t(s + 1)]) / std::max(area, 1e-300);
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = a;
          best_bin = s;
        }
      }
    }
    if (best_axis < 0) return {-1, begin, true};
    const bool leaf_better = double(n) <= best_cost;
    const float lo = cbounds.lo[best_axis], hi = cbounds.hi[best_axis];
    auto it = std::partition(index_.begin() + begin, index_.begin() + end,
                             [&](uint32_t i) { return bin_of(info_[i].centroid[best_axis], lo, hi) <= best_bin; });
    return {best_axis, uint32_t(it - index_.begin()), leaf_better};
  }

  std::pair<int, uint32_t> split_median(uint32_t begin, uint32_t end, const Box& cbounds) {
    const glm::vec3 e = cbounds.hi - cbounds.lo;
    const int axis = (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
    const uint32_t mid = begin + (end - begin) / 2;
    // Ties broken by index keep the build deterministic.
    std::nth_element(index_.begin() + begin, index_.begin() + mid, index_.begin() + end, [&](uint32_t a, uint32_t b) {
      const float ca = info_[a].centroid[axis], cb = info_[b].centroid[axis];
      return ca < cb || (ca == cb && a < b);
    });
    return {axis, mid};
  }

  int bin_of(float c, float lo, float hi) const {
    const int b = int(double(opt_.bins) * (double(c) - double(lo)) / (double(hi) - double(lo)));
    return std::clamp(b, 0, opt_.bins - 1);
  }

  static constexpr uint32_t kMaxDepth = kBvhStackSize - 1;
  BvhOptions opt_;
  std::vector<PrimInfo> info_;
  std::vector<uint32_t> index_;
  std::vector<BvhNode> nodes_;
  uint32_t depth_ = 0;
};

// The direction's reciprocal with zero (and denormal-tiny) components replaced
// by ±1e-300: huge but finite slab distances, so 0·∞ never makes a NaN, and
// the slabs stay exact for any geometry above 1e-290 units. The GLSL does the
// same with ±1e-30 (float).
glm::dvec3 safe_inverse(const glm::dvec3& d) {
  glm::dvec3 inv;
  for (int i = 0; i < 3; ++i) {
    const double di = std::fabs(d[i]) > 1e-300 ? d[i] : std::copysign(1e-300, d[i]);
    inv[i] = 1.0 / di;
  }
  return inv;
}

bool hits_box(const BvhNode& n, const glm::dvec3& o, const glm::dvec3& inv, double t_max) {
  const glm::dvec3 ta = (glm::dvec3(n.bounds_min) - o) * inv;
  const glm::dvec3 tb = (glm::dvec3(n.bounds_max) - o) * inv;
  const glm::dvec3 tmin = glm::min(ta, tb), tmax = glm::max(ta, tb);
  const double t0 = std::max(std::max(tmin.x, tmin.y), std::max(tmin.z, 0.0));
  // Widened by a few ulps so rounding never loses a box that a triangle inside
  // it is hit in (pbrt-v4 Bounds3::IntersectP, 1 + 2γ(3)).
  const double t1 = std::min(std::min(tmax.x, tmax.y), std::min(tmax.z, t_max)) * (1.0 + 1e-12);
  return t0 <= t1;
}

template <bool kAnyHit>
bool traverse(const Bvh& bvh, const Ray& ray, double t_max, SurfaceHit* hit) {
  const TriangleRay tr(ray);
  const glm::dvec3 inv = safe_inverse(ray.direction);
  const bool neg[3] = {ray.direction.x < 0.0, ray.direction.y < 0.0, ray.direction.z < 0.0};
  std::array<uint32_t, kBvhStackSize> stack;
  uint32_t sp = 0, node = 0;
  double t_closest = t_max;
  uint32_t found = UINT32_MAX;
  double fb1 = 0, fb2 = 0;
  for (;;) {
    const BvhNode& n = bvh.nodes[node];
    if (hits_box(n, ray.origin, inv, t_closest)) {
      if (n.is_leaf()) {
        for (uint32_t i = n.offset; i < n.offset + n.count; ++i) {
          double t, b1, b2;
          if (intersect_triangle(tr, bvh.triangles[i], t_closest, t, b1, b2)) {
            if constexpr (kAnyHit) return true;
            t_closest = t;
            found = i;
            fb1 = b1;
            fb2 = b2;
          }
        }
        if (sp == 0) break;
        node = stack[--sp];
      } else {
        // Near child first: the one on the ray's side of the split axis.
        if (neg[n.axis]) {
          stack[sp++] = node + 1;
          node = n.offset;
        } else {
          stack[sp++] = n.offset;
          node = node + 1;
        }
      }
    } else {
      if (sp == 0) break;
      node = stack[--sp];
    }
  }
  if (found == UINT32_MAX) return false;
  hit->t = t_closest;
  hit->primitive = found;
  hit->b1 = fb1;
  hit->b2 = fb2;
  finish_triangle_hit(bvh.triangles[found], ray, *hit);
  return true;
}

}  // namespace

Bvh build_bvh(std::vector<Triangle> triangles, const BvhOptions& options) {
  Builder builder(triangles, options);
  Bvh bvh;
  builder.run(bvh);
  bvh.triangles.reserve(triangles.size());
  for (uint32_t i : builder.order()) bvh.triangles.push_back(triangles[i]);
  return bvh;
}

bool intersect(const Bvh& bvh, const Ray& ray, double t_max, SurfaceHit& hit) {
  if (bvh.nodes.empty()) return false;  // default-constructed, never built
  return traverse<false>(bvh, ray, t_max, &hit);
}

bool occluded(const Bvh& bvh, const Ray& ray, double t_max) {
  if (bvh.nodes.empty()) return false;
  return traverse<true>(bvh, ray, t_max, nullptr);
}

bool intersect_brute_force(const std::vector<Triangle>& triangles, const Ray& ray, double t_max, SurfaceHit& hit) {
  const TriangleRay tr(ray);
  double t_closest = t_max;
  uint32_t found = UINT32_MAX;
  double fb1 = 0, fb2 = 0;
  for (uint32_t i = 0; i < triangles.size(); ++i) {
    double t, b1, b2;
    if (intersect_triangle(tr, triangles[i], t_closest, t, b1, b2)) {
      t_closest = t;
      found = i;
      fb1 = b1;
      fb2 = b2;
    }
  }
  if (found == UINT32_MAX) return false;
  hit.t = t_closest;
  hit.primitive = found;
  hit.b1 = fb1;
  hit.b2 = fb2;
  finish_triangle_hit(triangles[found], ray, hit);
  return true;
}

bool occluded_brute_force(const std::vector<Triangle>& triangles, const Ray& ray, double t_max) {
  const TriangleRay tr(ray);
  for (const Triangle& tri : triangles) {
    double t, b1, b2;
    if (intersect_triangle(tr, tri, t_max, t, b1, b2)) return true;
  }
  return false;
}

double sah_cost(const Bvh& bvh) {
  if (bvh.nodes.empty()) return 0.0;
  const double root = node_area(bvh.nodes[0]);
  if (!(root > 0.0)) return double(bvh.triangles.size());
  double cost = 0.0;
  for (const BvhNode& n : bvh.nodes) cost += node_area(n) / root * (n.is_leaf() ? double(n.count) : 1.0);
  return cost;
}

}  // namespace pyrolume::geometry
