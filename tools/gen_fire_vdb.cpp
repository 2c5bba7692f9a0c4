// gen_fire_vdb: writes a procedural fireball as an OpenVDB file laid out like a
// Blender smoke/fire cache: a `density` grid and a `temperature` grid on
// DIFFERENT lattices (temperature at twice the voxel size, density shifted by
// half a voxel), temperature in Blender's dimensionless unit (ambient 0, flames
// ~1..1.5) to be mapped to kelvin by the scene's temperature.scale/offset.
//
//   gen_fire_vdb OUT.vdb|OUT.nvdb [--resolution N] [--seed S] [--time T] [--sparse] [--thin-shell]
//                [--float] [--nvdb] [--exhaustive]
//
// --resolution: density voxels across the 3-unit-wide domain (default 64, at most 1024).
// --time T in [0,1]: the fireball rises, expands and cools as T grows (for
//   animation); default 0.35.
// --sparse: an explosion-like thin noisy shell with empty inside and outside
//   (large empty regions, for majorant-grid and sparse-tree tests). At
//   --resolution 1024 (seed 1, time 0.35): density 77.7 M active voxels in a
//   753 x 722 x 746 box (19 % of it), temperature 11.2 M at 374 x 359 x 352;
//   ~50 s of CPU (spread over the cores), ~0.5 GB peak memory (~0.95 GB with
//   --nvdb), a 166 MB .vdb or a 458 MB .nvdb.
// --thin-shell: the sparse shell (implies --sparse), larger and much thinner: a
//   fixed radius of 1.25 (not growing with --time) about a centre at height
//   1.65, nearly filling the domain (some seeds and times reach its sides and
//   are cut there), and density and temperature bands 0.2 times as wide
//   (--time still moves the noise and cools the heat). Made for a ~1000^3 box
//   with ~5 % of it active: at --resolution 1024 (seed 1, time 0.35): density
//   49.9 M active voxels in a 958 x 988 x 983 box (5.4 % of it), temperature
//   6.8 M at 464 x 475 x 446 (6.9 %); ~50 s of CPU, ~0.45 GB peak memory
//   (~0.86 GB with --nvdb), a 130 MB .vdb or a 417 MB .nvdb. --sparse without
//   it writes what it always has.
// --float: store 32-bit floats (default: half floats, as Blender and Houdini
//   caches usually are). Compression is blosc (+ active mask) when available.
// --nvdb, or OUT ending in .nvdb: write the same two grids as a NanoVDB file
//   instead (float grids, uncompressed, no file metadata), for readers without
//   OpenVDB; --float does not apply.
// --exhaustive: evaluate every voxel of the domain box, also for --sparse
//   (slow at high resolutions: the reference for the culling below).
// Deterministic: the noise is a hash of the integer lattice and the seed, no
// library random number generator is involved, and the trees do not depend on
// the thread count or on the culling.
//
// Evaluation: the domain box is cut into 8^3-voxel leaves of 4^3-voxel blocks,
// evaluated on all cores. The fireball evaluates every block. --sparse, where a
// leaf is at most kCullLeafWidth wide (density from --resolution 240,
// temperature from 480), evaluates only blocks near the shell: its band offset
// is sampled at every leaf's corners, then at the block corners of the leaves
// whose corners come within the band by less than their spread, and a block is
// evaluated when its corners do the same; then, until there is none, every
// block beside an evaluated block's face with active voxels on it. The culled
// trees equal --exhaustive's (seeds 1..3 x times 0, 0.35, 1 at resolution 256;
// seeds 1..3 at 512; seed 1 at 1024; --thin-shell: seeds 1..3 x times 0, 0.35,
// 1 at 256, seed 1 at 512 and 1024), and the output of the unculled
// evaluation is that of the earlier single-threaded generator.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <string>
#include <thread>
#include <vector>

#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

namespace {

// ---- noise: value noise on the integer lattice, quintic fade, fBm ----

uint32_t hash3(int32_t x, int32_t y, int32_t z, uint32_t seed) {
  // Murmur3-style finaliser over a linear mix: decorrelates neighbouring lattice points.
  uint32_t h = seed * 0x9E3779B1u;
  h ^= uint32_t(x) * 0x85EBCA77u;
  h = (h << 13) | (h >> 19);
  h ^= uint32_t(y) * 0xC2B2AE3Du;
  h = (h << 17) | (h >> 15);
  h ^= uint32_t(z) * 0x27D4EB2Fu;
  h ^= h >> 16;
  h *= 0x85EBCA6Bu;
  h ^= h >> 13;
  h *= 0xC2B2AE35u;
  h ^= h >> 16;
  return h;
}

double lattice(int32_t x, int32_t y, int32_t z, uint32_t seed) { return hash3(x, y, z, seed) * (1.0 / 4294967295.0); }

double fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }  // C2 smoothstep (Perlin 2002)

// The lattice values of the cell a value noise was last evaluated in, per
// thread and noise (first seed): neighbouring voxels mostly fall in the same
// cell of every octave but the finest, so its 8 hashes per seed are reused.
// Slot seed & 511 is a different slot for each noise here (they all use the
// seed + an offset below 512, and the offsets of first seeds are distinct); a
// shared slot would only cost time, as the cell is keyed by seed and position.
struct NoiseCell {
  int32_t x, y, z;
  uint32_t seed;
  size_t n;  // seeds (0: unused)
  double c[3][2][2][2];
};
thread_local NoiseCell noise_cells[512];

// N <= 3 value noises in [0,1] at one point, one per seed: they share the
// lattice cell and the fade weights (the warp evaluates three at each point),
// and each is the same arithmetic as a noise evaluated alone.
template <size_t N>
std::array<double, N> value_noise(double x, double y, double z, const std::array<uint32_t, N>& seeds) {
  static_assert(N >= 1 && N <= 3);
  const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  const int32_t ix = int32_t(fx), iy = int32_t(fy), iz = int32_t(fz);
  const double u = fade(x - fx), v = fade(y - fy), w = fade(z - fz);
  NoiseCell& cell = noise_cells[seeds[0] & 511u];
  if (cell.n != N || cell.x != ix || cell.y != iy || cell.z != iz || cell.seed != seeds[0]) {
    for (size_t s = 0; s < N; ++s)
      for (int a = 0; a < 2; ++a)
        for (int b = 0; b < 2; ++b)
          for (int d = 0; d < 2; ++d) cell.c[s][a][b][d] = lattice(ix + a, iy + b, iz + d, seeds[s]);
    cell.x = ix, cell.y = iy, cell.z = iz, cell.seed = seeds[0], cell.n = N;
  }
  auto lerp = [](double p, double q, double t) { return p + (q - p) * t; };
  std::array<double, N> out;
  for (size_t s = 0; s < N; ++s) {
    const double(&c)[2][2][2] = cell.c[s];
    out[s] = lerp(lerp(lerp(c[0][0][0], c[1][0][0], u), lerp(c[0][1][0], c[1][1][0], u), v),
                  lerp(lerp(c[0][0][1], c[1][0][1], u), lerp(c[0][1][1], c[1][1][1], u), v), w);
  }
  return out;
}

// Fractional Brownian motion: octaves at doubling frequency, halving amplitude;
// in [0,1]. N fBms at one point, one per seed, as above.
template <size_t N>
std::array<double, N> fbm(const openvdb::Vec3d& p, const std::array<uint32_t, N>& seeds, int octaves) {
  std::array<double, N> sum{};
  double amp = 0.5, norm = 0, f = 1;
  for (int o = 0; o < octaves; ++o) {
    std::array<uint32_t, N> s;
    for (size_t i = 0; i < N; ++i) s[i] = seeds[i] + 101u * uint32_t(o);
    const std::array<double, N> n = value_noise(p.x() * f, p.y() * f, p.z() * f, s);
    for (size_t i = 0; i < N; ++i) sum[i] += amp * n[i];
    norm += amp;
    amp *= 0.5;
    f *= 2.03;  // not exactly 2: keeps octave lattices from lining up
  }
  for (double& s : sum) s /= norm;
  return sum;
}
double fbm(const openvdb::Vec3d& p, uint32_t seed, int octaves = 5) { return fbm<1>(p, {seed}, octaves)[0]; }

double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// ---- the fire ----

struct Params {
  int resolution = 64;
  uint32_t seed = 1;
  double time = 0.35;
  bool sparse = false;
  bool thin = false;  // --thin-shell: the sparse shell, larger and thinner (sparse is set too)
  bool half = true;
  bool nvdb = false;        // write NanoVDB instead of OpenVDB
  bool exhaustive = false;  // evaluate every voxel, also for --sparse
};

// The sparse shell's half widths: density (temperature) is nonzero only where
// |shell offset| < its outer width, and at full strength where |offset| is
// within the inner one. The culling relies on the outer width.
struct Band {
  double outer, inner;
};
constexpr Band kDensityBand{0.14, 0.03}, kTemperatureBand{0.16, 0.02};
// --thin-shell: all four widths times 0.2, on a larger shell at a fixed place.
constexpr Band kThinDensityBand{0.028, 0.006}, kThinTemperatureBand{0.032, 0.004};
constexpr double kThinRadius = 1.25, kThinCentreHeight = 1.65;

// The fields at a world point. Domain: x, z in [-1.5, 1.5], y in [0, 3.5].
struct Fire {
  Params prm;
  openvdb::Vec3d centre;
  double radius, core_heat;
  Band density_band = kDensityBand, temperature_band = kTemperatureBand;  // the sparse shell's

  explicit Fire(const Params& p) : prm(p) {
    const double t = prm.time;
    centre = openvdb::Vec3d(0, 0.9 + 0.5 * t, 0);  // rises
    radius = 0.7 + 0.45 * t;                       // expands
    core_heat = 1.65 - 0.6 * t;                    // cools
    if (prm.thin) {
      centre = openvdb::Vec3d(0, kThinCentreHeight, 0);
      radius = kThinRadius;
      density_band = kThinDensityBand;
      temperature_band = kThinTemperatureBand;
    }
  }

  // Turbulent displacement: sample the noise at a warped point (domain warping).
  openvdb::Vec3d warp(const openvdb::Vec3d& p, double amount) const {
    // Two scales of warp: big billows, then finer curls on top.
    const openvdb::Vec3d q = p * 1.1 + openvdb::Vec3d(0, -1.5 * prm.time, 0);
    const auto n = fbm<3>(q, {prm.seed + 11, prm.seed + 23, prm.seed + 37}, 3);
    const openvdb::Vec3d w = p + amount * openvdb::Vec3d(n[0] - 0.5, n[1] - 0.5, n[2] - 0.5);
    const openvdb::Vec3d q2 = w * 3.1;
    const auto n2 = fbm<3>(q2, {prm.seed + 41, prm.seed + 43, prm.seed + 47}, 3);
    return w + 0.35 * amount * openvdb::Vec3d(n2[0] - 0.5, n2[1] - 0.5, n2[2] - 0.5);
  }

  // The sparse shell at p0: the offset from the middle of its noisy band (in
  // radii; the field is zero where |offset| >= its band) and the noise.
  struct Shell {
    double offset, noise;
  };
  Shell density_shell(const openvdb::Vec3d& p0) const {
    const openvdb::Vec3d p = warp(p0, 0.8);
    const double detail = fbm(p * 2.4, prm.seed + 1);
    const double r = (p - centre).length() / radius;
    return {r - 1.0 + 0.25 * (detail - 0.5), detail};
  }
  Shell temperature_shell(const openvdb::Vec3d& p0) const {
    const openvdb::Vec3d p = warp(p0, 0.7);
    const double r = (p - centre).length() / radius;
    const double n = fbm(p * 2.0, prm.seed + 3);
    return {r - 0.95 + 0.25 * (n - 0.5), n};
  }

  double density(const openvdb::Vec3d& p0) const {
    if (prm.sparse) {
      // Explosion shell: a noisy band around r = 1, nothing inside or outside.
      const Shell s = density_shell(p0);
      return 1.4 * smoothstep(density_band.outer, density_band.inner, std::abs(s.offset)) *
             smoothstep(0.3, 0.55, s.noise);
    }
    const openvdb::Vec3d p = warp(p0, 0.8);
    const double detail = fbm(p * 2.4, prm.seed + 1);
    const double r = (p - centre).length() / radius;
    // Fireball: moderate density (flames are thin), ragged edge.
    const double ball = smoothstep(1.0, 0.65, r + 0.45 * (detail - 0.5)) * (0.25 + 0.45 * detail);
    // Smoke plume above it: widens with height, densest just above the ball,
    // fading towards the top of the domain.
    const double h = p.y() - centre.y();
    double plume = 0.0;
    if (h > -0.2 * radius) {
      const double width = 0.45 * radius + 0.3 * std::max(h, 0.0);
      const double xz = std::hypot(p.x(), p.z()) / width;
      const double body = smoothstep(1.0, 0.45, xz + 0.6 * (fbm(p * 1.7 + openvdb::Vec3d(0, -2 * prm.time, 0),
                                                                  prm.seed + 5) -
                                                              0.5));
      plume = body * smoothstep(-0.2 * radius, 0.3 * radius, h) * smoothstep(3.4, 2.2, p.y()) *
              (0.55 + 0.8 * detail);
    }
    return std::max(ball, plume);
  }

  // Blender-style dimensionless temperature: 0 ambient, ~1.5 in the hot core.
  double temperature(const openvdb::Vec3d& p0) const {
    if (prm.sparse)
      return core_heat *
             smoothstep(temperature_band.outer, temperature_band.inner, std::abs(temperature_shell(p0).offset));
    const openvdb::Vec3d p = warp(p0, 0.7);
    const double r = (p - centre).length() / radius;
    const double n = fbm(p * 2.0, prm.seed + 3);
    // Hot core, ragged.
    const double core = core_heat * smoothstep(1.0, 0.25, r + 0.6 * (n - 0.5));
    // Flame tongues: thin high-frequency sheets licking up from the ball's
    // surface into the lower plume, where density is low to moderate.
    const double h = p.y() - centre.y();
    const double tongue_noise = fbm(p * 4.5 + openvdb::Vec3d(0, -3 * prm.time, 0), prm.seed + 7, 4);
    const double xz_flame = std::hypot(p.x() - centre.x(), p.z() - centre.z()) / radius;
    const double flames = (0.95 + 0.45 * n) * smoothstep(0.46, 0.6, tongue_noise) *
                          smoothstep(1.1, 0.5, xz_flame - 0.25 * std::max(h, 0.0) / radius) *
                          smoothstep(2.0 * radius, 0.2 * radius, h) * smoothstep(-1.2 * radius, -0.6 * radius, h);
    // The plume cools with height: smoky, mostly below a ~800 K cutoff.
    const double xz = std::hypot(p.x(), p.z()) / (0.45 * radius + 0.3 * std::max(h, 0.0));
    const double plume = 0.55 * std::exp(-1.3 * std::max(h, 0.0)) * smoothstep(1.0, 0.4, xz) *
                         smoothstep(-0.2 * radius, 0.2 * radius, h);
    return std::max({core, flames, plume});
  }
};

// ---- the grids ----

// Runs body(i) for i in [0, n) on every core, handing out indices in order.
template <class Body>
void parallel_for(size_t n, Body body) {
  std::atomic<size_t> next{0};
  auto work = [&] {
    for (size_t i; (i = next.fetch_add(1, std::memory_order_relaxed)) < n;) body(i);
  };
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < std::thread::hardware_concurrency(); ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
}

using Leaf = openvdb::FloatTree::LeafNodeType;  // 8^3 voxels
constexpr int kLeafDim = int(Leaf::DIM);
constexpr int kBlock = kLeafDim / 2;  // culling and flooding work on 4^3-voxel blocks, 8 per leaf

// The sparse shell's culling: the field is zero wherever |offset(p)| >= band.
struct Cull {
  std::function<double(const openvdb::Vec3d&)> offset;
  double band;
};

// Leaves at most this wide (world units) are culled; coarser lattices (a
// resolution up to ~240 for density) evaluate every voxel.
constexpr double kCullLeafWidth = 0.1;

// Whether some point among `n` samples of a shell offset, taken at the corners of
// a box, may lie within the band: the nearest sample, less the samples' spread
// (between the samples the offset may dip about that much).
bool near_band(const float* g, int n, double band) {
  float lo = INFINITY, hi = -INFINITY, nearest = INFINITY;
  for (int i = 0; i < n; ++i)
    lo = std::min(lo, g[i]), hi = std::max(hi, g[i]), nearest = std::min(nearest, std::abs(g[i]));
  return nearest - (hi - lo) < band;
}

// Builds one grid: voxel ijk holds f at world = voxel * ijk + offset (cell
// centred), for every ijk in the index box of [lo, hi]; voxels above
// `threshold` are active (a sparse tree, as simulators write). With `cull`,
// blocks away from the shell are skipped (see the top of the file).
template <class F>
openvdb::FloatGrid::Ptr make_grid(const std::string& name, double voxel, const openvdb::Vec3d& offset,
                                  const openvdb::Vec3d& lo, const openvdb::Vec3d& hi, double threshold, bool half,
                                  F f, const Cull* cull) {
  using openvdb::Coord;
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(name);
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  grid->setSaveFloatAsHalf(half);
  auto xf = openvdb::math::Transform::createLinearTransform(voxel);
  xf->postTranslate(offset);
  grid->setTransform(xf);
  const Coord a = Coord::floor(xf->worldToIndex(lo)), b = Coord::ceil(xf->worldToIndex(hi));
  auto world = [&](int i, int j, int k) { return xf->indexToWorld(Coord(i, j, k)); };

  // The leaves that meet the box: origins kLeafDim * (l0 + l), l in [0, n).
  const Coord l0(a.x() >> 3, a.y() >> 3, a.z() >> 3);
  const int n[3] = {(b.x() >> 3) - l0.x() + 1, (b.y() >> 3) - l0.y() + 1, (b.z() >> 3) - l0.z() + 1};
  const size_t leaves = size_t(n[0]) * n[1] * n[2];
  auto leaf_coord = [&](size_t li) {
    return Coord(l0.x() + int(li % n[0]), l0.y() + int(li / n[0] % n[1]), l0.z() + int(li / n[0] / n[1]));
  };
  auto leaf_index = [&](const Coord& l) {
    return (size_t(l.z() - l0.z()) * n[1] + size_t(l.y() - l0.y())) * n[0] + size_t(l.x() - l0.x());
  };

  std::vector<Leaf*> made(leaves, nullptr);  // the leaves with active voxels
  std::vector<uint8_t> done(leaves, 0);      // each leaf's evaluated blocks, bit bx + 2 by + 4 bz

  // Evaluates the blocks in `blocks` of leaf li (with `sample`, only those whose
  // corners' shell offsets come within the band); for each evaluated block, sets
  // bit 2 * axis + side (0: low, 1: high) of faces[block] for each of its faces
  // with an active voxel on it.
  auto eval_leaf = [&](size_t li, uint8_t blocks, bool sample, uint8_t* faces) {
    const Coord l = leaf_coord(li), o(l.x() * kLeafDim, l.y() * kLeafDim, l.z() * kLeafDim);
    if (sample) {
      float g[3][3][3];
      for (int k = 0; k < 3; ++k)
        for (int j = 0; j < 3; ++j)
          for (int i = 0; i < 3; ++i)
            g[k][j][i] = float(cull->offset(world(o.x() + kBlock * i, o.y() + kBlock * j, o.z() + kBlock * k)));
      for (int bit = 0; bit < 8; ++bit) {
        const int bx = bit & 1, by = bit >> 1 & 1, bz = bit >> 2;
        const float corners[8] = {g[bz][by][bx],         g[bz][by][bx + 1],         g[bz][by + 1][bx],
                                  g[bz][by + 1][bx + 1], g[bz + 1][by][bx],         g[bz + 1][by][bx + 1],
                                  g[bz + 1][by + 1][bx], g[bz + 1][by + 1][bx + 1]};
        if (!near_band(corners, 8, cull->band)) blocks &= uint8_t(~(1u << bit));
      }
    }
    done[li] |= blocks;
    for (int bit = 0; bit < 8; ++bit) {
      faces[bit] = 0;
      if (!(blocks >> bit & 1)) continue;
      const Coord bo = o.offsetBy((bit & 1) * kBlock, (bit >> 1 & 1) * kBlock, (bit >> 2) * kBlock);
      const Coord s = Coord::maxComponent(bo, a), e = Coord::minComponent(bo.offsetBy(kBlock - 1), b);
      for (int k = s.z(); k <= e.z(); ++k)
        for (int j = s.y(); j <= e.y(); ++j)
          for (int i = s.x(); i <= e.x(); ++i) {
            const Coord ijk(i, j, k);
            const double v = f(xf->indexToWorld(ijk));
            if (!(v > threshold)) continue;
            if (!made[li]) made[li] = new Leaf(o, 0.0f, false);
            made[li]->setValueOn(Leaf::coordToOffset(ijk), float(v));
            const Coord d = ijk - bo;
            for (int axis = 0; axis < 3; ++axis) {
              if (d[axis] == 0) faces[bit] |= uint8_t(1u << (2 * axis));
              if (d[axis] == kBlock - 1) faces[bit] |= uint8_t(2u << (2 * axis));
            }
          }
    }
  };

  // The first round: every block of every leaf, or with culling the leaves whose
  // corners' shell offsets come within the band (their blocks sampled again).
  const bool culling = cull && kLeafDim * voxel <= kCullLeafWidth;
  std::vector<size_t> todo;
  std::vector<uint8_t> todo_blocks;
  if (!culling) {
    todo.resize(leaves);
    for (size_t li = 0; li < leaves; ++li) todo[li] = li;
    todo_blocks.assign(leaves, 0xFF);
  } else {
    const size_t mx = size_t(n[0]) + 1, my = size_t(n[1]) + 1, mz = size_t(n[2]) + 1;  // leaf corners
    std::vector<float> g(mx * my * mz);
    parallel_for(my * mz, [&](size_t row) {
      const int j = (l0.y() + int(row % my)) * kLeafDim, k = (l0.z() + int(row / my)) * kLeafDim;
      for (size_t i = 0; i < mx; ++i) g[row * mx + i] = float(cull->offset(world((l0.x() + int(i)) * kLeafDim, j, k)));
    });
    for (size_t li = 0; li < leaves; ++li) {
      const Coord m = leaf_coord(li) - l0;
      float corners[8];
      for (int c = 0; c < 8; ++c)
        corners[c] = g[(size_t(m.z() + (c >> 2)) * my + size_t(m.y() + (c >> 1 & 1))) * mx + size_t(m.x() + (c & 1))];
      if (near_band(corners, 8, cull->band)) todo.push_back(li);
    }
    todo_blocks.assign(todo.size(), 0xFF);
  }

  // Evaluate; then, until there is none, every block not yet evaluated beside a
  // face with active voxels on it (with culling: pieces of the shell that the
  // samples missed; the culled trees have equalled --exhaustive's so far).
  bool sample = culling;
  std::vector<uint8_t> pending(leaves, 0);  // the next round's blocks, per leaf
  while (!todo.empty()) {
    std::vector<uint8_t> faces(todo.size() * 8);
    parallel_for(todo.size(), [&](size_t w) { eval_leaf(todo[w], todo_blocks[w], sample, &faces[w * 8]); });
    sample = false;
    std::vector<size_t> next;
    for (size_t w = 0; w < todo.size(); ++w)
      for (int bit = 0; bit < 8; ++bit)
        for (int side = 0; side < 6; ++side) {
          if (!(faces[w * 8 + bit] >> side & 1)) continue;
          // The neighbouring block, in blocks: 2 * leaf + (bx, by, bz).
          const Coord l = leaf_coord(todo[w]);
          Coord nb(2 * l.x() + (bit & 1), 2 * l.y() + (bit >> 1 & 1), 2 * l.z() + (bit >> 2));
          nb[side / 2] += side % 2 ? 1 : -1;
          const Coord nl(nb.x() >> 1, nb.y() >> 1, nb.z() >> 1);
          const int axis = side / 2;
          if (nl[axis] < l0[axis] || nl[axis] - l0[axis] >= n[axis]) continue;
          const size_t li = leaf_index(nl);
          const uint8_t nbit = uint8_t(1u << ((nb.x() & 1) + 2 * (nb.y() & 1) + 4 * (nb.z() & 1)));
          if ((done[li] | pending[li]) & nbit) continue;
          if (!pending[li]) next.push_back(li);
          pending[li] |= nbit;
        }
    todo_blocks.resize(next.size());
    for (size_t w = 0; w < next.size(); ++w) todo_blocks[w] = pending[next[w]], pending[next[w]] = 0;
    todo.swap(next);
  }
  for (Leaf* leaf : made)
    if (leaf) grid->tree().addLeaf(leaf);
  grid->pruneGrid();
  return grid;
}

// To stderr with status 2 for a bad command line; to stdout with 0 for --help.
int usage(bool asked = false) {
  (asked ? std::cout : std::cerr)
      << "usage: gen_fire_vdb OUT.vdb|OUT.nvdb [--resolution N] [--seed S] [--time T] [--sparse] [--thin-shell]"
         " [--float] [--nvdb] [--exhaustive]\n";
  if (asked)
    std::cout << "  --resolution N  density voxels across the 3-unit domain, 4..1024 (default 64)\n"
                 "  --seed S        noise seed (default 1)\n"
                 "  --time T        0..1: the fireball rises, expands and cools (default 0.35)\n"
                 "  --sparse        a thin noisy explosion shell, empty inside and outside\n"
                 "  --thin-shell    the --sparse shell (implied), larger (radius 1.25, not growing with --time)\n"
                 "                  and 5 times thinner: ~5 % of a ~1000^3 box active at --resolution 1024\n"
                 "  --float         store 32-bit floats (default: half floats)\n"
                 "  --nvdb          write NanoVDB (float, uncompressed); implied by OUT ending in .nvdb\n"
                 "  --exhaustive    evaluate every voxel of the box, also for --sparse (slow; a check)\n";
  return asked ? 0 : 2;
}

}  // namespace

int main(int argc, char** argv) {
  Params prm;
  std::string out;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* { return i + 1 < argc ? argv[++i] : nullptr; };
    const char* v = nullptr;
    if (a == "--help" || a == "-h") return usage(true);
    if (a == "--resolution" && (v = next())) prm.resolution = std::atoi(v);
    else if (a == "--seed" && (v = next())) prm.seed = uint32_t(std::strtoul(v, nullptr, 10));
    else if (a == "--time" && (v = next())) prm.time = std::atof(v);
    else if (a == "--sparse") prm.sparse = true;
    else if (a == "--thin-shell") prm.sparse = prm.thin = true;
    else if (a == "--float") prm.half = false;
    else if (a == "--nvdb") prm.nvdb = true;
    else if (a == "--exhaustive") prm.exhaustive = true;
    else if (!a.empty() && a[0] != '-' && out.empty()) out = a;
    else {
      const bool takes_value = a == "--resolution" || a == "--seed" || a == "--time";
      std::cerr << "gen_fire_vdb: " << a << (takes_value ? " needs a value" : ": unknown argument") << "\n";
      return usage();
    }
  }
  if (out.empty()) {
    std::cerr << "gen_fire_vdb: no output file given\n";
    return usage();
  }
  if (prm.resolution < 4 || prm.resolution > 1024 || !(prm.time >= 0 && prm.time <= 1)) {
    std::cerr << "gen_fire_vdb: --resolution " << prm.resolution << " --time " << prm.time
              << ": the resolution must be 4..1024 and the time in [0, 1]\n";
    return usage();
  }

  if (out.size() >= 5 && out.compare(out.size() - 5, 5, ".nvdb") == 0) prm.nvdb = true;

  openvdb::initialize();
  const Fire fire(prm);
  const openvdb::Vec3d lo(-1.5, 0.0, -1.5), hi(1.5, 3.5, 1.5);
  const double h = (hi.x() - lo.x()) / prm.resolution;
  // The sparse shell is culled to its band unless --exhaustive.
  const bool cull = prm.sparse && !prm.exhaustive;
  const Cull density_cull{[&](const openvdb::Vec3d& p) { return fire.density_shell(p).offset; },
                          fire.density_band.outer};
  const Cull temperature_cull{[&](const openvdb::Vec3d& p) { return fire.temperature_shell(p).offset; },
                              fire.temperature_band.outer};
  // Like a Blender export: density at voxel h with its lattice shifted by half
  // a voxel; temperature at 2h, unshifted. No sample point is shared.
  auto density = make_grid("density", h, openvdb::Vec3d(0.5 * h), lo, hi, 2e-3, prm.half,
                           [&](const openvdb::Vec3d& p) { return fire.density(p); }, cull ? &density_cull : nullptr);
  auto temperature = make_grid("temperature", 2 * h, openvdb::Vec3d(0.0), lo, hi, 1e-2, prm.half,
                               [&](const openvdb::Vec3d& p) { return fire.temperature(p); },
                               cull ? &temperature_cull : nullptr);
  const unsigned long long density_active = density->activeVoxelCount(),
                           temperature_active = temperature->activeVoxelCount();

  try {
    if (prm.nvdb) {
      // Converted one at a time, each OpenVDB tree dropped once converted.
      std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
      handles.push_back(nanovdb::openToNanoVDB(*density));
      density.reset();
      handles.push_back(nanovdb::openToNanoVDB(*temperature));
      temperature.reset();
      nanovdb::io::writeGrids(out, handles, nanovdb::io::Codec::NONE);
    } else {
      openvdb::io::File file(out);
      file.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
      openvdb::MetaMap meta;
      meta.insertMeta("creator", openvdb::StringMetadata("pyrolume/gen_fire_vdb"));
      meta.insertMeta("pyrolume/seed", openvdb::Int32Metadata(int32_t(prm.seed)));
      meta.insertMeta("pyrolume/resolution", openvdb::Int32Metadata(prm.resolution));
      meta.insertMeta("pyrolume/time", openvdb::DoubleMetadata(prm.time));
      const char* variant = prm.thin ? "thin sparse shell" : prm.sparse ? "sparse shell" : "fireball";
      meta.insertMeta("pyrolume/variant", openvdb::StringMetadata(variant));
      meta.insertMeta("pyrolume/temperature_unit",
                      openvdb::StringMetadata("dimensionless (Blender-like): 0 ambient, ~1.5 hottest; map with "
                                              "temperature.scale/offset"));
      file.write({density, temperature}, meta);
      file.close();
    }
  } catch (const std::exception& e) {  // openvdb::Exception, or NanoVDB's std::runtime_error
    std::cerr << out << ": cannot write: " << e.what() << "\n";
    return 1;
  }
  std::printf("%s: density %llu active voxels (voxel %.4g), temperature %llu active voxels (voxel %.4g)\n",
              out.c_str(), density_active, h, temperature_active, 2 * h);
  return 0;
}
