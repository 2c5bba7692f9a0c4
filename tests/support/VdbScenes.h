#pragma once
// Small VDB files for tests, scenes around them, and closed forms for the
// constant-box grid (shared by the CPU reference tests and the GPU tests). The
// files are written with the OpenVDB API in VdbScenes.cpp, compiled once into
// pyrolume_test_support: OpenVDB's templates cost ~11 s per translation unit.
//
// Conventions (docs/volumes.md, host/volume/VdbLoader.cpp): a `Lattice` maps
// voxel index ijk to world  offset + voxel · ijk  (OpenVDB's linear transform:
// voxel ijk's value sits at that point, the voxel's CENTRE). The renderers copy
// the active bounding box into a dense texture with one texel of zero padding
// on every side and interpolate trilinearly between texel centres. So a grid
// that is c on the active voxels lo..hi is exactly c only between the first and
// the last active voxel centres (`centre_box`), falls linearly to 0 over one
// voxel beyond them, and is 0 from the padding centres on (`support_box`, the
// extent the renderers clip rays to). ConstantBoxField reproduces that field
// exactly (independently of DenseGrid) and integrates it along rays exactly.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "color/Blackbody.h"
#include "render/cpu/Intersect.h"
#include "scene/Scene.h"
#include "support/AnalyticScenes.h"
#include "support/TestSupport.h"

namespace pyrolume::test {

// ------------------------------------------------------------ lattices ----

// Voxel ijk's centre is at world  offset + voxel · ijk.
struct Lattice {
  double voxel = 0.1;
  glm::dvec3 offset{0.0};
  glm::dvec3 world(const glm::dvec3& ijk) const { return offset + voxel * ijk; }
  glm::dvec3 index(const glm::dvec3& p) const { return (p - offset) / voxel; }
};

// Active voxels lo..hi inclusive.
struct VoxelBox {
  glm::ivec3 lo{0}, hi{0};
};

// World box between the first and last active voxel centres: where the
// trilinear lookup of a constant box equals the constant.
inline Bounds centre_box(const Lattice& l, const VoxelBox& b) {
  Bounds r;
  r.kind = Bounds::Kind::Box;
  r.min = l.world(glm::dvec3(b.lo));
  r.max = l.world(glm::dvec3(b.hi));
  return r;
}

// World box between the padding texel centres (lo − 1 .. hi + 1): the support
// of the trilinear field, the extent rays are clipped to.
inline Bounds support_box(const Lattice& l, const VoxelBox& b) {
  Bounds r;
  r.kind = Bounds::Kind::Box;
  r.min = l.world(glm::dvec3(b.lo) - 1.0);
  r.max = l.world(glm::dvec3(b.hi) + 1.0);
  return r;
}

// ------------------------------------------------------------- writing ----

using VoxelFn = std::function<float(int i, int j, int k)>;

// A float grid to write: every voxel of `box` active and set to value(i, j, k)
// (zeros included, so the active bbox is exactly `box`), grid class fog
// volume. NaN/Inf are written as they are (the loader must turn them into 0).
// value is called by write_vdb, within the statement that writes the file.
struct FloatGridSpec {
  std::string name;
  Lattice lattice;
  VoxelBox box;
  VoxelFn value;
};

inline FloatGridSpec make_float_grid(const std::string& name, const Lattice& l, const VoxelBox& box,
                                     const VoxelFn& value) {
  return FloatGridSpec{name, l, box, value};
}

// A grid of width × width × height voxels from the origin, standing along
// +z (z_up) or +y: its value at voxel (a, b, h) is f(a, b, h), a and b across
// the grid, h up its height.
inline FloatGridSpec upright_grid(const std::string& name, float voxel, int width, int height, bool z_up,
                                  const std::function<float(int a, int b, int h)>& f) {
  const VoxelBox box{{0, 0, 0}, z_up ? glm::ivec3(width - 1, width - 1, height - 1)
                                     : glm::ivec3(width - 1, height - 1, width - 1)};
  return make_float_grid(name, Lattice{voxel, glm::dvec3(0.0)}, box,
                         [=](int i, int j, int k) { return z_up ? f(i, j, k) : f(i, k, j); });
}

// A grid with no active voxels at all.
inline FloatGridSpec make_empty_grid(const std::string& name, const Lattice& l = {}) {
  return make_float_grid(name, l, VoxelBox{{0, 0, 0}, {-1, -1, -1}}, [](int, int, int) { return 0.0f; });
}

// File-level string metadata, as simulators write it ("creator", ...).
using FileMetadata = std::vector<std::pair<std::string, std::string>>;

// Writes the grids, in order, to one .vdb file; returns `file`.
std::filesystem::path write_vdb(const std::filesystem::path& file, const std::vector<FloatGridSpec>& grids,
                                const FileMetadata& metadata = {});

// "density" with two active voxels of value 1, at index (0, 0, 0) and at
// `far`, on OpenVDB's default unit transform: a tiny sparse grid whose dense
// box spans far + 1 voxels per axis.
std::filesystem::path write_two_voxels_vdb(const std::filesystem::path& file, const glm::ivec3& far);

// "density": n x n x n active tiles of value 1 from the origin, at OpenVDB
// tree level `level` (1: a lower node's 8³ tile, 2: an upper node's 128³,
// 3: a root tile of 4096³): a few hundred bytes of file describing
// n³ · side³ voxels.
std::filesystem::path write_tiles_vdb(const std::filesystem::path& file, int level, int n);

// How write_reader_paths_vdb compresses its grids (OpenVDB's io flags).
enum class VdbCompression { ZipActiveMask, Blosc, None };

// "density" (saved as half, 0.1 voxels, three voxels and an active lower-node
// tile) and "temperature" (float, one voxel), with file metadata ("creator"),
// compressed as asked: every path of the readers in ~2 KB, for damaging.
std::filesystem::path write_reader_paths_vdb(const std::filesystem::path& file, VdbCompression compression);

// Converts every grid of a .vdb file to one .nvdb file (NanoVDB, uncompressed).
// Float grids only (the test scenes write nothing else); others throw. With
// fp16, as NanoVDB's 16-bit quantised grids (Float16) instead of float.
void write_nanovdb_copy(const std::filesystem::path& vdb, const std::filesystem::path& nvdb, bool fp16 = false);

// A second grid for emission, on its own lattice (voxel size and offset may
// differ from the density's).
struct TemperatureBox {
  Lattice lattice;
  VoxelBox box;
  float value = 1.0f;
  std::string name = "temperature";
};

// "density" = c on the box (and optionally a constant temperature box).
inline std::filesystem::path write_constant_box_vdb(const std::filesystem::path& file, const Lattice& l,
                                                    const VoxelBox& box, float c,
                                                    const std::optional<TemperatureBox>& temperature = {}) {
  std::vector<FloatGridSpec> grids{make_float_grid("density", l, box, [c](int, int, int) { return c; })};
  if (temperature)
    grids.push_back(make_float_grid(temperature->name, temperature->lattice, temperature->box,
                                    [v = temperature->value](int, int, int) { return v; }));
  return write_vdb(file, grids);
}

// "density" = a + b · i (linear in x). Trilinear interpolation reproduces a
// linear field exactly, so inside the centre box ρ(p) = a + b · index(p).x.
inline std::filesystem::path write_ramp_x_vdb(const std::filesystem::path& file, const Lattice& l,
                                              const VoxelBox& box, float a, float b) {
  return write_vdb(file, {make_float_grid("density", l, box, [a, b](int i, int, int) { return a + b * float(i); })});
}

inline int floor_div(int a, int k) { return a >= 0 ? a / k : -((-a + k - 1) / k); }

// "density": a 3D checkerboard of `cell`³-voxel cells, `lo` and `hi` alternating.
inline std::filesystem::path write_checkerboard_vdb(const std::filesystem::path& file, const Lattice& l,
                                                    const VoxelBox& box, float lo, float hi, int cell = 1) {
  return write_vdb(file, {make_float_grid("density", l, box, [=](int i, int j, int k) {
                     return ((floor_div(i, cell) + floor_div(j, cell) + floor_div(k, cell)) & 1) ? hi : lo;
                   })});
}

// "density" with no active voxels.
inline std::filesystem::path write_empty_vdb(const std::filesystem::path& file) {
  return write_vdb(file, {make_empty_grid("density")});
}

// A sparse "explosion": a spherical shell of smoke (density peaks at mid-shell,
// 0 inside and outside; only shell voxels are active, so the tree is sparse
// while the dense box is mostly empty) with a hot inner rim ("temperature" in
// kelvin, from t_outer_k at the outer surface to t_inner_k at the inner one),
// centred on the lattice origin. Radii in voxels.
std::filesystem::path write_explosion_shell_vdb(const std::filesystem::path& file, const Lattice& l,
                                                double r_inner = 9.0, double r_outer = 14.0,
                                                float peak_density = 1.0f, float t_inner_k = 3000.0f,
                                                float t_outer_k = 600.0f);

// -------------------------------------------------------------- scenes ----

// Camera at (0, 0, −5) looking at the origin (AnalyticScenes' base), background 0.
inline Scene vdb_base_scene(int width, int height, int spp) { return analytic_base_scene(width, height, spp); }

// A `type: vdb` medium reading `file`, every other key at the scene format's
// default (the loader picks the grids by their default names).
inline Medium vdb_file_medium(const std::filesystem::path& file) {
  Medium m;
  m.type = Medium::Type::Vdb;
  m.file = file;
  return m;
}

// The same reading the grid "density", with the emission left at the default.
inline Medium vdb_density_medium(const std::string& name, const std::filesystem::path& file, glm::dvec3 sigma_a,
                                 glm::dvec3 sigma_s, double g = 0.0) {
  Medium m = vdb_file_medium(file);
  m.name = name;
  m.density_grid = "density";
  m.sigma_a = sigma_a;
  m.sigma_s = sigma_s;
  m.g = g;
  return m;
}

// A `type: vdb` medium reading `file` ("density"; "temperature" when it emits
// from a grid). Le_rgb set: constant emission scale · rgb × density; unset and
// temperature_emission: blackbody of the grid temperature; else no emission.
inline Medium vdb_medium(const std::string& name, const std::filesystem::path& file, glm::dvec3 sigma_a,
                         glm::dvec3 sigma_s, double g = 0.0, std::optional<glm::dvec3> Le_rgb = std::nullopt,
                         double emission_scale = 1.0, bool temperature_emission = false) {
  Medium m = vdb_density_medium(name, file, sigma_a, sigma_s, g);
  m.emission.scale = emission_scale;
  m.emission.rgb = Le_rgb;
  m.emission.is_grid = !Le_rgb && temperature_emission;
  // The closed forms of these scenes use the colour-only normalisation (not
  // the scene default), so the expected Le stays of order 1 at any temperature.
  m.emission.blackbody = BlackbodyMode::Seed;
  if (m.emission.is_grid) m.temperature_grid = "temperature";
  if (!Le_rgb && !temperature_emission) m.emission.scale = 0.0;  // emits nothing
  return m;
}

// The ramp the transmittance tests share: "density" = a + b·i on voxels
// i = 0..20 of a 0.1-unit lattice, y and z in −5..5 (a, b and every value
// exact in half).
struct RampX {
  Lattice lat{0.1, {0.0, 0.0, 0.0}};
  VoxelBox box{{0, -5, -5}, {20, 5, 5}};
  float a = 0.5f, b = 0.125f;
  float operator()(int i, int, int) const { return a + b * float(i); }
  // The ramp as a vdb medium, its file written into dir.
  Medium medium(const std::filesystem::path& dir, glm::dvec3 sigma_a, glm::dvec3 sigma_s) const {
    return vdb_medium("ramp", write_ramp_x_vdb(dir / "ramp.vdb", lat, box, a, b), sigma_a, sigma_s);
  }
};

// -------------------------------------------------------- closed forms ----

// The trilinear field of a constant box grid as the renderers sample it:
//   ρ(p) = c · h(u.x; lo.x, hi.x) · h(u.y; ...) · h(u.z; ...),  u = lattice index of p,
//   h(u; lo, hi) = clamp(min(u − (lo − 1), (hi + 1) − u), 0, 1),
// (trilinear weights are separable, and the 1D interpolant of "c on lo..hi, 0
// on the padding" is that trapezoid). `c` must be the value AS STORED (round to
// half first for R16F textures; exact for 0.5, 0.75, 2 ...). No medium transform.
struct ConstantBoxField {
  Lattice lattice;
  VoxelBox box;
  double c = 1.0;

  static double hat(double u, int lo, int hi) {
    return std::clamp(std::min(u - (lo - 1.0), (hi + 1.0) - u), 0.0, 1.0);
  }
  double density(const glm::dvec3& p) const {
    const glm::dvec3 u = lattice.index(p);
    return c * hat(u.x, box.lo.x, box.hi.x) * hat(u.y, box.lo.y, box.hi.y) * hat(u.z, box.lo.z, box.hi.z);
  }

  // ∫_{t0}^{t1} ρ(o + t d) dt, exact: along a ray each hat is piecewise linear in
  // t with kinks where u crosses lo − 1, lo, hi, hi + 1, so between kinks ρ is a
  // polynomial of degree <= 3, which 3-point Gauss–Legendre integrates exactly.
  double optical_depth(const glm::dvec3& o, const glm::dvec3& d, double t0, double t1) const {
    if (!(t1 > t0)) return 0.0;
    double ts[14] = {t0, t1};
    int n = 2;
    const glm::dvec3 uo = lattice.index(o), ud = d / lattice.voxel;
    for (int a = 0; a < 3; ++a) {
      if (ud[a] == 0.0) continue;
      for (double k : {box.lo[a] - 1.0, double(box.lo[a]), double(box.hi[a]), box.hi[a] + 1.0}) {
        const double t = (k - uo[a]) / ud[a];
        if (t > t0 && t < t1) ts[n++] = t;
      }
    }
    std::sort(ts, ts + n);
    static const double x[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, w[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    double sum = 0.0;
    for (int i = 0; i + 1 < n; ++i) {
      const double a = ts[i], b = ts[i + 1];
      if (!(b > a)) continue;
      if (!std::isfinite(b)) break;  // ρ = 0 beyond the last kink
      const double m = 0.5 * (a + b), h = 0.5 * (b - a);
      for (int q = 0; q < 3; ++q) sum += w[q] * h * density(o + (m + h * x[q]) * d);
    }
    return sum;
  }

  // τ over the whole ray t >= 0 (the kinks bound every piece; beyond the last ρ = 0).
  double optical_depth(const glm::dvec3& o, const glm::dvec3& d) const { return optical_depth(o, d, 0.0, 1e300); }

  // Signature for pixel_average's refinement: changes wherever τ is not smooth.
  int signature(const glm::dvec3& o, const glm::dvec3& d) const {
    return chord(support_box(lattice, box), o, d).signature * 1000 + chord(centre_box(lattice, box), o, d).signature;
  }
};

// Radiance of a single-medium grid scene with constant emission Le = scale ·
// rgb and σa/σt the same everywhere, when no path scatters (σs = 0 or
// max_depth 0), from the optical depth τ = ∫ρ along the ray: the absorbed
// fraction σa/σt of the extinction emits, since σa(x)/σt(x) is the same at
// every x:
//   L = (σa/σt)·Le·(1 − e^{−σt τ}) + bg·e^{−σt τ},  σ = sigma · density_scale.
inline glm::dvec3 uniform_albedo_radiance(const Scene& s, double tau) {
  const Medium& m = s.media.at(0);
  const glm::dvec3 Le = m.emission.emits() && m.emission.rgb ? m.emission.scale * *m.emission.rgb : glm::dvec3(0.0);
  glm::dvec3 L;
  for (int c = 0; c < 3; ++c) {
    const double sa = m.sigma_a[c] * m.density_scale, st = (m.sigma_a[c] + m.sigma_s[c]) * m.density_scale;
    const double T = std::exp(-st * tau);
    L[c] = (st > 0.0 ? sa / st * Le[c] * (1.0 - T) : 0.0) + s.background[c] * T;
  }
  return L;
}

// The same along a ray through one vdb medium whose density is `field`.
inline glm::dvec3 constant_box_radiance(const Scene& s, const ConstantBoxField& field, const glm::dvec3& o,
                                        const glm::dvec3& d, int* sig = nullptr) {
  if (sig) *sig = field.signature(o, d);
  return uniform_albedo_radiance(s, field.optical_depth(o, d));
}

// Pixel means of any per-ray closed form (jittered box filter), for
// ztest_against_exact. Coarser refinement than single_collision_exact's
// defaults: a grid's radiance is continuous across its edge ramp (τ is), so
// only true jumps (signature changes, e.g. a hot region's boundary) need deep
// refinement. Measured on cpu_vdb_test's oblique constant-box and temperature-
// lattice scenes: base 16 / level 6 / steep 0.02 (8–25× slower) moves no pixel by
// more than 6e-4 absolute, 0.07 of its standard error at 512–1024 spp.
inline std::function<glm::dvec3(int, int)> exact_image(
    const Scene& s, const std::function<glm::dvec3(const glm::dvec3& o, const glm::dvec3& d, int* sig)>& L,
    int base = 8, int max_level = 4, double steep_rel = 0.2) {
  const int W = s.film.width, H = s.film.height;
  auto img = std::make_shared<std::vector<glm::dvec3>>(size_t(W) * H);
  auto Lf = [&](double fx, double fy, int* sig) {
    return L(s.camera.position, film_ray(s.camera, W, H, fx, fy), sig);
  };
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) (*img)[size_t(y) * W + x] = pixel_average(Lf, x, y, base, max_level, steep_rel);
  return [img, W](int x, int y) { return (*img)[size_t(y) * W + x]; };
}

inline std::function<glm::dvec3(int, int)> constant_box_exact(const Scene& s, const ConstantBoxField& field) {
  return exact_image(s, [&s, field](const glm::dvec3& o, const glm::dvec3& d, int* sig) {
    return constant_box_radiance(s, field, o, d, sig);
  });
}


// ------------------------------------------- general trilinear fields ----

// The trilinear field of ANY grid whose active voxels fill `box` with
// value(i, j, k) (the values AS STORED: round to half first for R16F), zero
// padding around, sampled as the renderers do (voxel ijk's value at its centre,
// linear in between; 0 beyond one voxel outside the box). Written
// independently of DenseGrid. No medium transform. Values are cached at
// construction (plus the one-texel padding), so lookups are cheap.
struct TrilinearVoxelField {
  Lattice lattice;
  VoxelBox box;
  glm::ivec3 dims{0};       // box size plus one padding texel on each side
  std::vector<double> v;    // x fastest

  TrilinearVoxelField() = default;
  TrilinearVoxelField(const Lattice& l, const VoxelBox& b, const VoxelFn& value) : lattice(l), box(b) {
    dims = b.hi - b.lo + 3;
    v.assign(size_t(dims.x) * dims.y * dims.z, 0.0);
    for (int k = b.lo.z; k <= b.hi.z; ++k)
      for (int j = b.lo.y; j <= b.hi.y; ++j)
        for (int i = b.lo.x; i <= b.hi.x; ++i) {
          const double x = value(i, j, k);
          at(i, j, k) = std::isfinite(x) && x > 0.0 ? x : 0.0;  // the loader's NaN/negative rule
        }
  }
  double& at(int i, int j, int k) {
    return v[(size_t(k - box.lo.z + 1) * dims.y + size_t(j - box.lo.y + 1)) * dims.x + size_t(i - box.lo.x + 1)];
  }
  double get(int i, int j, int k) const {
    if (i < box.lo.x || j < box.lo.y || k < box.lo.z || i > box.hi.x || j > box.hi.y || k > box.hi.z) return 0.0;
    return v[(size_t(k - box.lo.z + 1) * dims.y + size_t(j - box.lo.y + 1)) * dims.x + size_t(i - box.lo.x + 1)];
  }
  double density(const glm::dvec3& p) const {
    const glm::dvec3 u = lattice.index(p);
    const glm::dvec3 f = glm::floor(u);
    const glm::ivec3 i0(f);
    const glm::dvec3 w = u - f;
    double r = 0.0;
    for (int c = 0; c < 8; ++c) {
      const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
      const double wt = (dx ? w.x : 1.0 - w.x) * (dy ? w.y : 1.0 - w.y) * (dz ? w.z : 1.0 - w.z);
      if (wt != 0.0) r += wt * get(i0.x + dx, i0.y + dy, i0.z + dz);
    }
    return r;
  }
  // ∫_{t0}^{t1} ρ(o + t d) dt, exact: between crossings of the lattice planes
  // (voxel centres) trilinear interpolation is a product of three linear
  // functions of t, a cubic, which 3-point Gauss–Legendre integrates exactly.
  // Only the support (padding centres lo − 1 .. hi + 1) is integrated.
  double optical_depth(const glm::dvec3& o, const glm::dvec3& d, double t0, double t1) const {
    const glm::dvec3 uo = lattice.index(o), ud = d / lattice.voxel;
    double a = t0, b = t1;
    for (int ax = 0; ax < 3; ++ax) {
      const double lo = box.lo[ax] - 1.0, hi = box.hi[ax] + 1.0;
      if (ud[ax] == 0.0) {
        if (uo[ax] <= lo || uo[ax] >= hi) return 0.0;
        continue;
      }
      double ta = (lo - uo[ax]) / ud[ax], tb = (hi - uo[ax]) / ud[ax];
      if (ta > tb) std::swap(ta, tb);
      a = std::max(a, ta);
      b = std::min(b, tb);
    }
    if (!(b > a)) return 0.0;
    std::vector<double> ts{a, b};
    for (int ax = 0; ax < 3; ++ax) {
      if (ud[ax] == 0.0) continue;
      for (int k = box.lo[ax] - 1; k <= box.hi[ax] + 1; ++k) {
        const double t = (k - uo[ax]) / ud[ax];
        if (t > a && t < b) ts.push_back(t);
      }
    }
    std::sort(ts.begin(), ts.end());
    static const double x[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, w[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    double sum = 0.0;
    for (size_t i = 0; i + 1 < ts.size(); ++i) {
      const double m = 0.5 * (ts[i] + ts[i + 1]), h = 0.5 * (ts[i + 1] - ts[i]);
      if (!(h > 0.0)) continue;
      for (int q = 0; q < 3; ++q) sum += w[q] * h * density(o + (m + h * x[q]) * d);
    }
    return sum;
  }
  double optical_depth(const glm::dvec3& o, const glm::dvec3& d) const { return optical_depth(o, d, 0.0, 1e300); }
  int signature(const glm::dvec3& o, const glm::dvec3& d) const {
    return chord(support_box(lattice, box), o, d).signature * 1000 + chord(centre_box(lattice, box), o, d).signature;
  }
};

// Per-channel transmittance exp(−σt_c·density_scale·τ) along each camera ray
// to infinity, pixel-averaged (what VulkanHooks::debug_mode 1/2 estimates)
// for a single grid medium whose density is `field`.
template <class Field>
std::function<glm::dvec3(int, int)> transmittance_exact(const Scene& s, const Field& field, int base = 4,
                                                        int max_level = 4, double steep_rel = 0.05) {
  const Medium& m = s.media.at(0);
  const glm::dvec3 sigma_t = (m.sigma_a + m.sigma_s) * m.density_scale;
  return exact_image(
      s,
      [sigma_t, &field](const glm::dvec3& o, const glm::dvec3& d, int* sig) {
        const double tau = field.optical_depth(o, d);
        if (sig) *sig = field.signature(o, d);
        return glm::exp(-sigma_t * tau);
      },
      base, max_level, steep_rel);
}

// The constant box both backends' vdb tests render (cpu_vdb_test,
// vulkan_vdb_test): 17 × 13 × 15 voxels of 0.1 holding c = 0.75 (exact in
// half), viewed obliquely; the VDB is written into `dir`.
struct ConstantBoxSetup {
  explicit ConstantBoxSetup(const std::string& tag) : dir(temp_dir(tag)) {}
  std::filesystem::path dir;
  Lattice lat{0.1, {0.02, -0.01, 0.03}};
  VoxelBox box{{-8, -6, -7}, {8, 6, 7}};
  float c = 0.75f;

  Scene constant_box_scene(int w, int h, int spp, glm::dvec3 sigma_a, glm::dvec3 sigma_s,
                           std::optional<glm::dvec3> Le = glm::dvec3(1.0, 0.6, 0.3), double scale = 1.5) {
    Scene s = vdb_base_scene(w, h, spp);
    s.camera.position = {2.0, 1.5, -4.0};
    s.camera.look_at = {0.1, 0.05, 0.0};
    s.background = {0.05, 0.1, 0.2};
    s.media.push_back(
        vdb_medium("box", write_constant_box_vdb(dir / "box.vdb", lat, box, c), sigma_a, sigma_s, 0.3, Le, scale));
    s.media[0].density_scale = 1.5;
    return s;
  }
  ConstantBoxField field() const { return {lat, box, double(c)}; }

  // The box with a temperature grid `tb` (1 on its voxels) that emits only
  // where it is hot: T = (v − (1 − 1e-4)) · 6e7 K puts the stored 1.0 at
  // 6000 K and everything below v = 0.99990 at or under cutoff_k (100 K), so
  // the emitting region is tb's centre box (its trilinear ramp emits only
  // within 1e-4 of a voxel of it: a 1e-5 relative effect). max_depth 0: σs
  // only extinguishes (and keeps the two estimators from coinciding sample by
  // sample: with σs = 0 every tentative collision in the hot region is real).
  Scene hot_box_scene(const std::string& file, const TemperatureBox& tb) const {
    Scene s = vdb_base_scene(24, 24, 2048);
    s.camera.position = {1.5, 1.0, -4.0};
    s.camera.look_at = {0.0, 0.0, 0.0};
    s.camera.fov_deg = 22.0;
    s.background = {0.02, 0.02, 0.05};
    s.integrator.max_depth = 0;
    s.media.push_back(vdb_medium("box", write_constant_box_vdb(dir / file, lat, box, c, tb), {0.8, 1.2, 1.6},
                                 {0.4, 0.3, 0.2}, 0.0, std::nullopt, 2.0, true));
    s.media[0].temperature.offset = 1.0 - 1e-4;
    s.media[0].temperature.scale = 6000.0 / 1e-4;
    s.media[0].temperature.cutoff_k = 100.0;
    return s;
  }
  // hot_box_scene's exact image, with the emission inside `hot` only. σa/σt is
  // the same everywhere, so over the hot chord [ta, tb]
  //   ∫ σa(t) Le e^{−σt τ(t)} dt = (σa/σt)·Le·(e^{−σt τ(ta)} − e^{−σt τ(tb)}).
  std::function<glm::dvec3(int, int)> hot_box_exact(const Scene& s, const Bounds& hot) const {
    const glm::dvec3 Le = 2.0 * color::blackbody_rgb(6000.0, BlackbodyMode::Seed);
    const ConstantBoxField f = field();
    const glm::dvec3 sigma_a = s.media[0].sigma_a, sigma_t = s.media[0].sigma_a + s.media[0].sigma_s;
    const glm::dvec3 bg = s.background;
    return exact_image(s, [&](const glm::dvec3& o, const glm::dvec3& d, int* sig) {
      const double tau = f.optical_depth(o, d);
      const cpu::RayInterval h = cpu::intersect_box(o, d, hot.min, hot.max);
      double ta = 0, tb = 0;
      if (h.hit && h.t1 > 0.0) ta = std::max(0.0, h.t0), tb = h.t1;
      const double tau_a = f.optical_depth(o, d, 0.0, ta), tau_b = f.optical_depth(o, d, 0.0, tb);
      if (sig) *sig = f.signature(o, d) + 7 * chord(hot, o, d).signature;
      glm::dvec3 L;
      for (int k = 0; k < 3; ++k)
        L[k] = sigma_a[k] / sigma_t[k] * Le[k] * (std::exp(-sigma_t[k] * tau_a) - std::exp(-sigma_t[k] * tau_b)) +
               bg[k] * std::exp(-sigma_t[k] * tau);
      return L;
    });
  }
};

// Media that transmit everything: a grid with no active voxels and an
// all-zero grid (σa = σs = 1), written into `dir` (both transmittance tests).
inline void add_empty_and_zero_grids(Scene& s, const std::filesystem::path& dir) {
  s.media.push_back(vdb_medium("empty", write_empty_vdb(dir / "empty.vdb"), {1, 1, 1}, {1, 1, 1}));
  s.media.push_back(vdb_medium("zero", write_constant_box_vdb(dir / "zero.vdb", {0.1, {}}, {{-3, -3, -3}, {3, 3, 3}}, 0.0f),
                               {1, 1, 1}, {1, 1, 1}));
}

}  // namespace pyrolume::test
