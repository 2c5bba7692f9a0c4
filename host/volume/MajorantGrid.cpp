#include "volume/MajorantGrid.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "volume/SparseGrid.h"

namespace pyrolume {

glm::ivec3 default_majorant_resolution(glm::ivec3 dims) {
  glm::ivec3 r;
  for (int a = 0; a < 3; ++a) r[a] = std::clamp((dims[a] + 15) / 16, 1, 64);
  return r;
}

namespace {
glm::dvec3 dims_over(glm::ivec3 dims, glm::ivec3 res) { return glm::dvec3(dims) / glm::dvec3(res); }
}  // namespace

MajorantGrid build_majorant_grid(const DenseGrid& g, glm::ivec3 res) {
  MajorantGrid m;
  m.res = glm::max(res, glm::ivec3(1));
  m.cell_size = dims_over(g.dims, m.res);
  m.max_density.assign(size_t(m.res.x) * m.res.y * m.res.z, 0.0f);
  if (g.empty()) return m;
  // Texel range [lo, hi] of each cell along one axis.
  auto range = [&](int axis, int c, int& lo, int& hi) {
    double a = c * m.cell_size[axis], b = (c + 1) * m.cell_size[axis];
    lo = std::max(0, int(std::floor(a - 0.5)));
    hi = std::min(g.dims[axis] - 1, int(std::floor(b - 0.5)) + 1);
  };
  if (g.is_sparse()) {
    // The same maxima, scattered from the tree's nonzero voxels instead of
    // gathered over the box: the cells whose texel range holds texel t, per axis.
    std::vector<glm::ivec2> cells_of[3];
    for (int a = 0; a < 3; ++a) {
      cells_of[a].assign(size_t(g.dims[a]), glm::ivec2(std::numeric_limits<int>::max(), -1));
      for (int c = 0; c < m.res[a]; ++c) {
        int lo, hi;
        range(a, c, lo, hi);
        for (int t = lo; t <= hi; ++t) {
          cells_of[a][size_t(t)].x = std::min(cells_of[a][size_t(t)].x, c);
          cells_of[a][size_t(t)].y = std::max(cells_of[a][size_t(t)].y, c);
        }
      }
    }
    g.sparse->for_each_nonzero([&](const glm::ivec3& ijk, float v) {
      const glm::ivec3 t = ijk - g.origin;
      if (!(v > 0.0f) || glm::any(glm::lessThan(t, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(t, g.dims))) return;
      const glm::ivec2 X = cells_of[0][size_t(t.x)], Y = cells_of[1][size_t(t.y)], Z = cells_of[2][size_t(t.z)];
      for (int cz = Z.x; cz <= Z.y; ++cz)
        for (int cy = Y.x; cy <= Y.y; ++cy)
          for (int cx = X.x; cx <= X.y; ++cx) {
            float& mx = m.max_density[(size_t(cz) * m.res.y + cy) * m.res.x + cx];
            mx = std::max(mx, v);
          }
    });
    return m;
  }
  for (int cz = 0; cz < m.res.z; ++cz)
    for (int cy = 0; cy < m.res.y; ++cy)
      for (int cx = 0; cx < m.res.x; ++cx) {
        int x0, x1, y0, y1, z0, z1;
        range(0, cx, x0, x1);
        range(1, cy, y0, y1);
        range(2, cz, z0, z1);
        float mx = 0.0f;
        for (int k = z0; k <= z1; ++k)
          for (int j = y0; j <= y1; ++j)
            for (int i = x0; i <= x1; ++i) mx = std::max(mx, g.texel(i, j, k));
        m.max_density[(size_t(cz) * m.res.y + cy) * m.res.x + cx] = mx;
      }
  return m;
}

namespace {

// splitmix64: a fixed, portable sequence for the cost simulation.
struct CostRng {
  uint64_t state;
  double next() {
    uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return double((z ^ (z >> 31)) >> 11) * 0x1.0p-53;
  }
  glm::dvec3 direction() {
    const double z = 1.0 - 2.0 * next(), phi = 6.283185307179586 * next(), r = std::sqrt(std::max(0.0, 1.0 - z * z));
    return {r * std::cos(phi), r * std::sin(phi), z};
  }
};

// Where the line p + t·v is inside the texel box [0, dims]: [t0, t1] (t0 > t1: never).
void box_span(glm::dvec3 p, glm::dvec3 v, glm::dvec3 dims, double& t0, double& t1) {
  t0 = -std::numeric_limits<double>::infinity();
  t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (v[a] == 0.0) {
      if (p[a] < 0.0 || p[a] > dims[a]) t0 = 1.0, t1 = 0.0;
      continue;
    }
    double ta = -p[a] / v[a], tb = (dims[a] - p[a]) / v[a];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
}

}  // namespace

double tracking_cost(const DenseGrid& g, const MajorantGrid& m, double sigma_t_per_density, double albedo,
                     CellCosts costs) {
  if (g.empty() || !(sigma_t_per_density > 0.0)) return 0.0;
  CostRng rng{0x5eed};
  const glm::dvec3 dims(g.dims);
  // World directions to texel-space velocities: t stays a world distance.
  const glm::dmat3 to_texel(g.world_to_index);
  const glm::dvec3 to_index = glm::dvec3(g.origin) - 0.5;  // texel coords -> index coords
  double cost = 0.0;
  for (int ray = 0; ray < kCostRays; ++ray) {
    const double ray_start = cost;
    glm::dvec3 p(rng.next() * dims.x, rng.next() * dims.y, rng.next() * dims.z);
    glm::dvec3 v = to_texel * rng.direction();
    double t0, t1;
    box_span(p, v, dims, t0, t1);
    p += t0 * v;  // the line's entry into the texture
    for (int bounce = 0; bounce <= kCostBounces; ++bounce) {
      box_span(p, v, dims, t0, t1);
      double t = std::max(t0, 0.0);
      bool collided = false;
      // 3D DDA over the cells, delta tracking inside each.
      glm::ivec3 cell = glm::clamp(glm::ivec3(glm::floor((p + (t + 1e-9) * v) / m.cell_size)), glm::ivec3(0), m.res - 1);
      while (t < t1 && !collided) {
        double t_exit = t1;
        int axis = -1;
        for (int a = 0; a < 3; ++a) {
          if (v[a] == 0.0) continue;
          const double face = (cell[a] + (v[a] > 0.0 ? 1 : 0)) * m.cell_size[a];
          const double ta = (face - p[a]) / v[a];
          if (ta < t_exit) t_exit = ta, axis = a;
        }
        const double sigma_maj = m.at(cell.x, cell.y, cell.z) * sigma_t_per_density;
        cost += sigma_maj > 0.0 ? costs.cell : costs.empty;
        while (sigma_maj > 0.0) {
          t -= std::log(1.0 - rng.next()) / sigma_maj;
          if (t >= t_exit) break;
          cost += 1.0;  // a density lookup
          if (cost - ray_start >= kCostCapPerRay) break;
          const double sigma = g.sample_index(p + t * v + to_index) * sigma_t_per_density;
          if (rng.next() * sigma_maj < sigma) {
            collided = true;
            break;
          }
        }
        if (collided || axis < 0 || cost - ray_start >= kCostCapPerRay) break;
        t = t_exit;
        cell[axis] += v[axis] > 0.0 ? 1 : -1;
        if (cell[axis] < 0 || cell[axis] >= m.res[axis]) break;
      }
      if (!collided || cost - ray_start >= kCostCapPerRay || rng.next() >= albedo) break;
      p += t * v;
      v = to_texel * rng.direction();
    }
  }
  return cost / kCostRays;
}

glm::ivec3 choose_majorant_resolution(const DenseGrid& g, double sigma_t_per_density, double albedo, CellCosts costs) {
  const glm::ivec3 coarsest = default_majorant_resolution(g.dims);
  if (g.empty() || !(sigma_t_per_density > 0.0)) return coarsest;
  int finest = 0;
  auto cells = [](glm::ivec3 r) { return size_t(r.x) * size_t(r.y) * size_t(r.z); };
  while (finest < 3 && cells(coarsest * (2 << finest)) <= kMaxMajorantCells) ++finest;
  MajorantGrid m = build_majorant_grid(g, coarsest * (1 << finest));
  glm::ivec3 best = m.res;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int j = finest;; --j) {
    const double c = tracking_cost(g, m, sigma_t_per_density, albedo, costs);
    if (c <= best_cost) best_cost = c, best = m.res;  // ties go to the coarser
    if (j == 0) break;
    // Max-pool 2×2×2: cell c of the coarser grid is cells 2c, 2c + 1 of this one.
    MajorantGrid coarse;
    coarse.res = m.res / 2;
    coarse.cell_size = dims_over(g.dims, coarse.res);
    coarse.max_density.assign(cells(coarse.res), 0.0f);
    for (int z = 0; z < m.res.z; ++z)
      for (int y = 0; y < m.res.y; ++y)
        for (int x = 0; x < m.res.x; ++x) {
          float& c2 = coarse.max_density[(size_t(z / 2) * coarse.res.y + y / 2) * coarse.res.x + x / 2];
          c2 = std::max(c2, m.at(x, y, z));
        }
    m = std::move(coarse);
  }
  return best;
}

}  // namespace pyrolume
