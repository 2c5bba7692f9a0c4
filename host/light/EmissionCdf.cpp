#include "light/EmissionCdf.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <unordered_map>

#include "color/Blackbody.h"
#include "color/ColorSpace.h"
#include "color/EmissionModel.h"
#include "light/PiecewiseConstant.h"
#include "scene/MediumVolume.h"
#include "volume/SparseGrid.h"

namespace pyrolume {

namespace {

glm::dmat4 translation(const glm::dvec3& t) {
  glm::dmat4 m(1.0);
  m[3] = glm::dvec4(t, 1.0);
  return m;
}

}  // namespace

EmissionParams EmissionParams::from_medium(const Medium& m) {
  EmissionParams p;
  p.sigma_a = m.sigma_a * m.density_scale;
  p.temperature = m.temperature;
  p.emission = m.emission;
  if (m.emission.emits()) {
    if (m.emission.rgb) {
      p.emits_rgb = true;
      p.Le_rgb = m.emission.scale * *m.emission.rgb;
    } else if (needs_temperature_grid(m)) {
      p.emits_temperature = true;
    }
  }
  return p;
}

EmissionCdf EmissionCdf::build(const Medium& m, const StoredVolume& vol) {
  const DenseGrid* temperature = vol.temperature && !vol.temperature->grid.empty() ? &vol.temperature->grid : nullptr;
  return build(vol.density.grid, temperature, EmissionParams::from_medium(m));
}

// Flat CDF over the cells of weight > 0 (the cells that can emit), chosen over a
// two-level (majorant block, then cell) scheme:
//  - building is one pass over the cells, O(N): 40 ms for the 1.17 M cells of
//    assets/volumes/fire.vdb (Release, one core);
//  - only cells that can emit are searched (15 % of fire.vdb's box: 176 k
//    entries), so a sample is one binary search of ≤ 18 steps, fewer dependent
//    loads than the two searches of a two-level scheme;
//  - a dense per-cell pmf array makes pdf(x) one load, with no search, and
//    direction_pdf one load per cell crossed.
EmissionCdf EmissionCdf::build(const DenseGrid& density, const DenseGrid* temperature, const EmissionParams& p) {
  const auto t0 = std::chrono::steady_clock::now();
  EmissionCdf e;
  if (density.empty() || density.dims.x < 2 || density.dims.y < 2 || density.dims.z < 2) return e;
  e.cells_ = density.dims - 1;
  e.cell_to_world_ = density.index_to_world * translation(glm::dvec3(density.origin));
  e.world_to_cell_ = glm::inverse(e.cell_to_world_);
  e.cell_volume_ = std::abs(glm::determinant(glm::dmat3(e.cell_to_world_)));
  const glm::ivec3 C = e.cells_;
  const size_t ncell = e.cell_count();

  // E(T) = Y(σa ⊙ Le(T)) per temperature texel (memoised on the stored value:
  // R16F grids hold at most 65536 distinct values).
  auto E_of_value = [&](float value) -> double {
    const double T = p.temperature.kelvin(value);
    if (!temperature_emits(T, p.temperature.cutoff_k)) return 0.0;  // NaN too
    const glm::dvec3 Le = temperature_Le(T, p.temperature.cutoff_k, p.emission.scale, p.emission.blackbody,
                                         p.emission.observer, p.emission.adapt_to_k);
    return color::srgb_luminance(p.sigma_a * Le);
  };
  const bool grid_emits = p.emits_temperature && temperature && !temperature->empty();
  if (!(p.emits_rgb || grid_emits)) return e;
  std::vector<float> E_t;
  double E_outside = 0.0;  // E at the temperature texture's outside (value 0)
  if (!p.emits_rgb) {
    std::unordered_map<uint32_t, double> memo;
    E_t.resize(temperature->texel_count());
    const glm::ivec3 TD = temperature->dims;
    for (size_t k = 0; k < E_t.size(); ++k) {
      const float v = temperature->is_sparse()
                          ? temperature->texel(int(k % size_t(TD.x)), int((k / size_t(TD.x)) % size_t(TD.y)),
                                               int(k / (size_t(TD.x) * size_t(TD.y))))
                          : temperature->values[k];
      uint32_t bits;
      std::memcpy(&bits, &v, 4);
      auto it = memo.find(bits);
      if (it == memo.end()) it = memo.emplace(bits, E_of_value(v)).first;
      E_t[k] = float(it->second);
    }
    E_outside = E_of_value(0.0f);
  }
  const double E_rgb = p.emits_rgb ? color::srgb_luminance(p.sigma_a * p.Le_rgb) : 0.0;
  if (p.emits_rgb && !(E_rgb > 0.0)) return e;

  // Density cell coordinates -> temperature texel coordinates (affine).
  glm::dmat4 d2t(1.0);
  glm::dvec3 t_base(0.0), t_neg(0.0), t_pos(0.0);
  glm::dmat3 t_lin(1.0);
  if (!p.emits_rgb) {
    d2t = translation(-glm::dvec3(temperature->origin)) * temperature->world_to_index * e.cell_to_world_;
    t_lin = glm::dmat3(d2t);
    t_base = glm::dvec3(d2t[3]);
    // The image of the unit cube is base + L·c + [Σ min(0, L_col), Σ max(0, L_col)].
    for (int col = 0; col < 3; ++col)
      for (int r = 0; r < 3; ++r) {
        t_neg[r] += std::min(0.0, t_lin[col][r]);
        t_pos[r] += std::max(0.0, t_lin[col][r]);
      }
  }
  const glm::ivec3 TD = p.emits_rgb ? glm::ivec3(0) : temperature->dims;
  // Lookups in float on the GPU may land a hair outside the exact footprint.
  constexpr double kSlack = 1e-4;
  auto E_footprint = [&](int i, int j, int k) -> double {
    const glm::dvec3 base = t_base + t_lin * glm::dvec3(i, j, k);
    const glm::dvec3 lo = base + t_neg - kSlack, hi = base + t_pos + kSlack;
    glm::ivec3 a, b;
    bool outside = false;
    for (int ax = 0; ax < 3; ++ax) {
      a[ax] = int(std::floor(lo[ax]));
      b[ax] = int(std::floor(hi[ax])) + 1;
      if (a[ax] < 0 || b[ax] > TD[ax] - 1) outside = true;
      a[ax] = std::max(a[ax], 0);
      b[ax] = std::min(b[ax], TD[ax] - 1);
    }
    double m = outside ? E_outside : 0.0;
    for (int z = a.z; z <= b.z; ++z)
      for (int y = a.y; y <= b.y; ++y) {
        const float* row = &E_t[(size_t(z) * TD.y + y) * TD.x];
        for (int x = a.x; x <= b.x; ++x) m = std::max(m, double(row[x]));
      }
    return m;
  };

  e.weight_.assign(ncell, 0.0f);
  std::vector<double> w;
  std::vector<uint32_t> entries;
  const glm::ivec3 D = density.dims;
  auto rho = [&](int x, int y, int z) {
    return density.is_sparse() ? density.texel(x, y, z) : density.values[(size_t(z) * D.y + y) * D.x + x];
  };
  for (int k = 0; k < C.z; ++k)
    for (int j = 0; j < C.y; ++j)
      for (int i = 0; i < C.x; ++i) {
        float r = 0.0f;
        for (int c = 0; c < 8; ++c) r = std::max(r, rho(i + (c & 1), j + ((c >> 1) & 1), k + (c >> 2)));
        if (!(r > 0.0f)) continue;
        const double E = p.emits_rgb ? E_rgb : E_footprint(i, j, k);
        const double wc = double(r) * E;
        if (!(wc > 0.0)) continue;
        const size_t cell = (size_t(k) * C.y + j) * C.x + i;
        e.weight_[cell] = float(wc);
        w.push_back(wc);
        entries.push_back(uint32_t(cell));
      }
  if (w.empty()) {
    e.weight_.clear();
    return e;
  }
  double total = 0.0;
  for (double x : w) total += x;
  e.power_ = total * e.cell_volume_;

  e.entries_ = std::move(entries);
  e.set_distribution(w);
  e.build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return e;
}

void EmissionCdf::set_distribution(const std::vector<double>& w) {
  const int n = int(w.size());
  std::vector<float> cdf(size_t(n) + 1);
  build_cdf(w.data(), n, cdf.data());
  cdf_.assign(cdf.begin() + 1, cdf.end());  // inclusive: cdf_[j] = P(entry <= j)
  pmf_.assign(cell_count(), 0.0f);
  for (int j = 0; j < n; ++j) pmf_[entries_[j]] = float(bin_probability(cdf.data(), j));
}

EmissionCdf EmissionCdf::blocks(int b) const {
  if (empty() || b <= 1) return *this;
  const auto t0 = std::chrono::steady_clock::now();
  EmissionCdf e;
  const glm::ivec3 C = cells_;
  e.cells_ = (C + (b - 1)) / b;
  glm::dmat4 scale(1.0);
  scale[0][0] = scale[1][1] = scale[2][2] = double(b);
  e.cell_to_world_ = cell_to_world_ * scale;
  e.world_to_cell_ = glm::inverse(e.cell_to_world_);
  e.cell_volume_ = cell_volume_ * double(b) * b * b;
  e.power_ = power_;
  const size_t nblock = e.cell_count();
  std::vector<double> sum(nblock, 0.0);
  for (int k = 0; k < C.z; ++k)
    for (int j = 0; j < C.y; ++j)
      for (int i = 0; i < C.x; ++i) {
        const float w = weight_[size_t(linear_cell({i, j, k}))];
        if (w > 0.0f) sum[size_t(e.linear_cell({i / b, j / b, k / b}))] += double(w);
      }
  std::vector<double> w;
  e.weight_.assign(nblock, 0.0f);
  for (size_t c = 0; c < nblock; ++c)
    if (sum[c] > 0.0) {
      e.weight_[c] = float(sum[c] / (double(b) * b * b));  // mean weight per unit volume
      w.push_back(sum[c]);
      e.entries_.push_back(uint32_t(c));
    }
  e.set_distribution(w);
  e.build_seconds_ = build_seconds_ + std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return e;
}

EmissionCdf EmissionCdf::build_sparse_blocks(const DenseGrid& density, const DenseGrid* temperature,
                                             const EmissionParams& p, int b) {
  const auto t0 = std::chrono::steady_clock::now();
  EmissionCdf e;
  if (!density.is_sparse() || density.dims.x < 2 || density.dims.y < 2 || density.dims.z < 2) return e;
  b = std::max(b, 1);
  const glm::ivec3 C = density.dims - 1;  // cells, as build()'s
  e.cells_ = (C + (b - 1)) / b;
  const glm::dmat4 cell_to_world = density.index_to_world * translation(glm::dvec3(density.origin));
  glm::dmat4 scale(1.0);
  scale[0][0] = scale[1][1] = scale[2][2] = double(b);
  e.cell_to_world_ = cell_to_world * scale;
  e.world_to_cell_ = glm::inverse(e.cell_to_world_);
  const double cell_volume = std::abs(glm::determinant(glm::dmat3(cell_to_world)));
  e.cell_volume_ = cell_volume * double(b) * b * b;
  const size_t nblock = e.cell_count();

  auto E_of_value = [&](float value) -> double {
    const double T = p.temperature.kelvin(value);
    if (!temperature_emits(T, p.temperature.cutoff_k)) return 0.0;
    const glm::dvec3 Le = temperature_Le(T, p.temperature.cutoff_k, p.emission.scale, p.emission.blackbody,
                                         p.emission.observer, p.emission.adapt_to_k);
    return color::srgb_luminance(p.sigma_a * Le);
  };
  const bool grid_emits = p.emits_temperature && temperature && !temperature->empty();
  if (!(p.emits_rgb || grid_emits)) return e;
  // E_max per block.
  std::vector<float> E(nblock, 0.0f);
  if (p.emits_rgb) {
    std::fill(E.begin(), E.end(), float(color::srgb_luminance(p.sigma_a * p.Le_rgb)));
  } else {
    std::fill(E.begin(), E.end(), float(E_of_value(0.0f)));  // where no leaf is, the value is 0
    // Temperature index -> density cell coordinates (affine).
    const glm::dmat4 t2c = glm::inverse(cell_to_world) * temperature->index_to_world;
    // The range of the temperature values whose trilinear footprint reaches
    // into each block (a voxel is read within one of its own voxels; a hair
    // more for the float lookups), then E_max from the range's ends (E grows
    // with T).
    constexpr double kReach = 1.0 + 1e-3;
    std::vector<float> vlo(nblock, std::numeric_limits<float>::infinity()), vhi(nblock, -vlo[0]);
    const glm::dvec3 reach = glm::abs(glm::dvec3(t2c[0])) + glm::abs(glm::dvec3(t2c[1])) + glm::abs(glm::dvec3(t2c[2]));
    auto add_value = [&](const glm::dvec3& index, float v) {
      const glm::dvec3 c(t2c * glm::dvec4(index, 1.0));
      const glm::dvec3 lo = c - kReach * reach, hi = c + kReach * reach;
      glm::ivec3 a, z;
      for (int ax = 0; ax < 3; ++ax) {
        if (!(hi[ax] >= 0.0 && lo[ax] < double(C[ax]))) return;  // misses the cells
        a[ax] = int(std::max(0.0, std::floor(lo[ax]))) / b;
        z[ax] = int(std::min(double(C[ax] - 1), std::floor(hi[ax]))) / b;
      }
      for (int k = a.z; k <= z.z; ++k)
        for (int j = a.y; j <= z.y; ++j)
          for (int i = a.x; i <= z.x; ++i) {
            const size_t at = size_t(e.linear_cell({i, j, k}));
            vlo[at] = std::min(vlo[at], v);
            vhi[at] = std::max(vhi[at], v);
          }
    };
    if (temperature->is_sparse()) {
      temperature->sparse->for_each_nonzero([&](const glm::ivec3& ijk, float v) { add_value(glm::dvec3(ijk), v); });
    } else {
      const glm::ivec3 TD = temperature->dims;
      for (int k = 0; k < TD.z; ++k)
        for (int j = 0; j < TD.y; ++j)
          for (int i = 0; i < TD.x; ++i)
            if (const float v = temperature->texel(i, j, k); v != 0.0f)
              add_value(glm::dvec3(temperature->origin + glm::ivec3(i, j, k)), v);
    }
    for (size_t c = 0; c < nblock; ++c)
      if (vlo[c] <= vhi[c]) E[c] = float(std::max({double(E[c]), E_of_value(vlo[c]), E_of_value(vhi[c])}));
  }
  // Σρ per block: a nonzero voxel at texel t is a corner of cells t − 1 and t per axis.
  std::vector<double> rho(nblock, 0.0);
  density.sparse->for_each_nonzero([&](const glm::ivec3& ijk, float v) {
    if (!(v > 0.0f)) return;
    const glm::ivec3 t = ijk - density.origin;
    glm::ivec3 a, z;
    for (int ax = 0; ax < 3; ++ax) {
      a[ax] = std::max(t[ax] - 1, 0) / b;
      z[ax] = std::min(t[ax], C[ax] - 1) / b;
      if (t[ax] < 0 || t[ax] > C[ax]) return;
    }
    for (int k = a.z; k <= z.z; ++k)
      for (int j = a.y; j <= z.y; ++j)
        for (int i = a.x; i <= z.x; ++i) rho[size_t(e.linear_cell({i, j, k}))] += double(v);
  });
  std::vector<double> w;
  e.weight_.assign(nblock, 0.0f);
  double total = 0.0;
  for (size_t c = 0; c < nblock; ++c) {
    const double wc = rho[c] * double(E[c]);
    if (!(wc > 0.0)) continue;
    e.weight_[c] = float(wc / (double(b) * b * b));  // mean weight per unit volume, as blocks()
    w.push_back(wc);
    e.entries_.push_back(uint32_t(c));
    total += wc;
  }
  if (w.empty()) {
    e.weight_.clear();
    e.entries_.clear();
    return e;
  }
  e.power_ = total * cell_volume;
  e.set_distribution(w);
  e.build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return e;
}

EmissionCdf EmissionCdf::build_light(const Medium& m, const StoredVolume& vol) {
  // A sparse grid whose box has room for per-cell arrays gets the dense
  // grid's light exactly (its lookups read the tree); a larger one the blocks.
  const glm::ivec3 C = vol.density.grid.dims - 1;
  if (vol.density.grid.is_sparse() && uint64_t(C.x) * uint64_t(C.y) * uint64_t(C.z) > kMaxCellsForCellLight) {
    const DenseGrid* temperature = vol.temperature && !vol.temperature->grid.empty() ? &vol.temperature->grid : nullptr;
    const EmissionCdf blocks = build_sparse_blocks(vol.density.grid, temperature, EmissionParams::from_medium(m),
                                                   light_block(vol.density.grid.dims - 1));
    return blocks.clustered(light_cluster(blocks.cells()));
  }
  const EmissionCdf cells = build(m, vol);
  const EmissionCdf blocks = cells.blocks(light_block(cells.cells()));
  return blocks.clustered(light_cluster(blocks.cells()));
}

int EmissionCdf::light_block(const glm::ivec3& cells) { return light_block(cells, kLightBlocksPerAxis); }

int EmissionCdf::light_block(const glm::ivec3& cells, int per_axis) {
  const int longest = std::max(cells.x, std::max(cells.y, cells.z));
  return std::max(1, (longest + per_axis - 1) / per_axis);
}

double EmissionCdf::cell_weight(const glm::ivec3& c) const {
  if (weight_.empty() || glm::any(glm::lessThan(c, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(c, cells_)))
    return 0.0;
  return weight_[size_t(linear_cell(c))];
}

glm::ivec3 EmissionCdf::cell_coords(uint32_t cell) const {
  const uint32_t X = uint32_t(cells_.x), Y = uint32_t(cells_.y);
  return glm::ivec3(int(cell % X), int((cell / X) % Y), int(cell / (X * Y)));
}

uint32_t EmissionCdf::first_above(const std::vector<float>& cdf, uint32_t lo, uint32_t hi, double u) {
  while (lo < hi) {
    const uint32_t mid = (lo + hi) / 2;
    if (double(cdf[mid]) <= u)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

EmissionSample EmissionCdf::sample(double u, const glm::dvec3& u3) const {
  EmissionSample s;
  if (empty()) return s;
  const uint32_t cell = entries_[first_above(cdf_, 0u, uint32_t(cdf_.size()) - 1u, u)];
  s.cell = cell;
  s.p = cell_to_world(glm::dvec3(cell_coords(cell)) + u3);
  s.pdf = double(pmf_[cell]) / cell_volume_;
  return s;
}

double EmissionCdf::pdf(const glm::dvec3& p) const {
  if (empty()) return 0.0;
  const glm::dvec3 c = world_to_cell(p);
  const glm::dvec3 f = glm::floor(c);
  if (f.x < 0 || f.y < 0 || f.z < 0 || f.x >= cells_.x || f.y >= cells_.y || f.z >= cells_.z) return 0.0;
  return double(pmf_[size_t(linear_cell(glm::ivec3(f)))]) / cell_volume_;
}

template <class F>
void EmissionCdf::walk_cells(const glm::dvec3& o, const glm::dvec3& w, F f) const {
  // The map to cell coordinates is affine, so the ray keeps its parameter t
  // (world distance, w unit length) there: c(t) = co + t·cw.
  const glm::dvec3 co = world_to_cell(o);
  const glm::dvec3 cw = glm::dvec3(world_to_cell_ * glm::dvec4(w, 0.0));
  const glm::dvec3 n(cells_);
  double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (cw[a] == 0.0) {
      if (co[a] < 0.0 || co[a] >= n[a]) return;
      continue;
    }
    const double ta = -co[a] / cw[a], tb = (n[a] - co[a]) / cw[a];
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  }
  if (!(t0 < t1)) return;
  // 3D DDA (Amanatides & Woo 1987) over the cells the ray crosses.
  glm::ivec3 cell = glm::clamp(glm::ivec3(glm::floor(co + cw * t0)), glm::ivec3(0), cells_ - 1);
  glm::ivec3 step(0);
  glm::dvec3 t_next(std::numeric_limits<double>::infinity()), t_delta(std::numeric_limits<double>::infinity());
  for (int a = 0; a < 3; ++a) {
    if (cw[a] > 0.0) {
      step[a] = 1;
      t_next[a] = (cell[a] + 1 - co[a]) / cw[a];
      t_delta[a] = 1.0 / cw[a];
    } else if (cw[a] < 0.0) {
      step[a] = -1;
      t_next[a] = (cell[a] - co[a]) / cw[a];
      t_delta[a] = -1.0 / cw[a];
    }
  }
  double t = t0;
  while (t < t1) {
    const int a = t_next.x <= t_next.y ? (t_next.x <= t_next.z ? 0 : 2) : (t_next.y <= t_next.z ? 1 : 2);
    const double tb = std::min(t_next[a], t1);
    f(cell, t, tb);
    t = tb;
    cell[a] += step[a];
    if (cell[a] < 0 || cell[a] >= cells_[a]) break;
    t_next[a] += t_delta[a];
  }
}

double EmissionCdf::direction_pdf(const glm::dvec3& o, double norm, const glm::dvec3& w) const {
  if (empty() || !(norm > 0.0)) return 0.0;
  // In each cell the volume pdf is constant, and ∫ t² dt over [ta, tb] is (tb³ − ta³)/3.
  double sum = 0.0;
  if (!is_clustered()) {
    walk_cells(o, w, [&](const glm::ivec3& c, double ta, double tb) {
      sum += double(pmf_[size_t(linear_cell(c))]) * (tb - ta) * (tb * tb + tb * ta + ta * ta);  // tb³ − ta³
    });
    return sum / (3.0 * cell_volume_);
  }
  size_t last = clusters_.size();
  double importance = 0.0;
  walk_cells(o, w, [&](const glm::ivec3& c, double ta, double tb) {
    const float q = local_pmf_[size_t(linear_cell(c))];
    if (!(q > 0.0f)) return;
    const size_t s = cluster_of(c);
    if (s != last) importance = cluster_importance(o, last = s);
    sum += importance * double(q) * (tb - ta) * (tb * tb + tb * ta + ta * ta);
  });
  return sum / (3.0 * cell_volume_ * norm);
}

size_t EmissionCdf::cluster_of(const glm::ivec3& cell) const {
  const glm::ivec3 s = cell / cluster_k_;
  return (size_t(s.z) * cluster_dims_.y + s.y) * cluster_dims_.x + s.x;
}

double EmissionCdf::cluster_importance(const glm::dvec3& o, size_t s) const {
  const Cluster& c = clusters_[s];
  const glm::dvec3 d = o - c.centre;
  return c.power / std::max(glm::dot(d, d), c.radius2);
}

double EmissionCdf::receiver_norm(const glm::dvec3& o) const {
  if (!is_clustered()) return empty() ? 0.0 : 1.0;
  double z = 0.0;
  for (size_t s = 0; s < clusters_.size(); ++s)
    if (clusters_[s].power > 0.0) z += cluster_importance(o, s);
  return z;
}

EmissionSample EmissionCdf::sample_from(const glm::dvec3& o, double norm, double u, double u_cell,
                                        const glm::dvec3& u3) const {
  if (!is_clustered()) return sample(u_cell, u3);
  EmissionSample s;
  if (empty() || !(norm > 0.0)) return s;
  // The cluster: the first whose running sum of I_s exceeds u·norm (the last
  // nonempty one if rounding leaves none), then u_cell the cell (lights.glsl
  // emission_sample: the same searches).
  const double target = u * norm;
  double acc = 0.0, share = 0.0;
  size_t pick = clusters_.size();
  for (size_t k = 0; k < clusters_.size(); ++k) {
    if (!(clusters_[k].power > 0.0)) continue;
    const double i = cluster_importance(o, k);
    pick = k;
    share = i;
    acc += i;
    if (target < acc) break;
  }
  const Cluster& c = clusters_[pick];
  const uint32_t cell = entries_[first_above(local_cdf_, c.first, c.first + c.count - 1u, u_cell)];
  s.cell = cell;
  s.p = cell_to_world(glm::dvec3(cell_coords(cell)) + u3);
  s.pdf = share / norm * double(local_pmf_[cell]) / cell_volume_;
  return s;
}

double EmissionCdf::pdf_from(const glm::dvec3& o, double norm, const glm::dvec3& p) const {
  if (!is_clustered()) return pdf(p);
  const glm::dvec3 f = glm::floor(world_to_cell(p));
  if (f.x < 0 || f.y < 0 || f.z < 0 || f.x >= cells_.x || f.y >= cells_.y || f.z >= cells_.z) return 0.0;
  const glm::ivec3 c(f);
  const double q = local_pmf_[size_t(linear_cell(c))];
  if (!(q > 0.0) || !(norm > 0.0)) return 0.0;
  return cluster_importance(o, cluster_of(c)) / norm * q / cell_volume_;
}

EmissionCdf EmissionCdf::clustered(int k) const {
  if (empty()) return *this;
  EmissionCdf e = *this;
  k = std::max(k, 1);
  e.cluster_k_ = k;
  e.cluster_dims_ = (cells_ + (k - 1)) / k;
  const size_t n = size_t(e.cluster_dims_.x) * e.cluster_dims_.y * e.cluster_dims_.z;
  e.clusters_.assign(n, Cluster{});
  // Entries grouped by cluster, ascending cells inside (a stable sort of the
  // ascending entries); the static CDF is rebuilt in that order.
  std::vector<uint32_t> order = entries_;
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return e.cluster_of(cell_coords(a)) < e.cluster_of(cell_coords(b));
  });
  e.entries_ = order;
  std::vector<double> w(order.size());
  double total = 0.0;
  for (size_t j = 0; j < order.size(); ++j) total += w[j] = double(weight_[order[j]]);
  e.set_distribution(w);
  e.local_cdf_.assign(order.size(), 0.0f);
  e.local_pmf_.assign(cell_count(), 0.0f);
  std::vector<float> cdf;
  for (size_t j = 0; j < order.size();) {
    const size_t s = e.cluster_of(cell_coords(order[j]));
    size_t end = j;
    glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
    double sum = 0.0;
    while (end < order.size() && e.cluster_of(cell_coords(order[end])) == s) {
      const glm::dvec3 c(cell_coords(order[end]));
      lo = glm::min(lo, c);
      hi = glm::max(hi, c + 1.0);
      sum += w[end];
      ++end;
    }
    Cluster& cl = e.clusters_[s];
    cl.first = uint32_t(j);
    cl.count = uint32_t(end - j);
    cl.power = sum / total;
    // Bounding sphere of the box [lo, hi] in world space (the map is affine,
    // so the box's image is a parallelepiped whose corners bound it).
    cl.centre = cell_to_world(0.5 * (lo + hi));
    for (int corner = 0; corner < 8; ++corner) {
      const glm::dvec3 p = cell_to_world({corner & 1 ? hi.x : lo.x, corner & 2 ? hi.y : lo.y, corner & 4 ? hi.z : lo.z});
      cl.radius2 = std::max(cl.radius2, glm::dot(p - cl.centre, p - cl.centre));
    }
    const int m = int(end - j);
    cdf.assign(size_t(m) + 1, 0.0f);
    build_cdf(w.data() + j, m, cdf.data());
    for (int i = 0; i < m; ++i) {
      e.local_cdf_[j + size_t(i)] = cdf[size_t(i) + 1];
      e.local_pmf_[order[j + size_t(i)]] = float(bin_probability(cdf.data(), i));
    }
    j = end;
  }
  return e;
}

size_t EmissionCdf::nonempty_clusters() const {
  size_t n = 0;
  for (const Cluster& c : clusters_) n += c.count > 0 ? 1 : 0;
  return n;
}

}  // namespace pyrolume
