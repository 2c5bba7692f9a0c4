// gen_fire_vdb: writes a procedural fireball as an OpenVDB file laid out like a
// Blender smoke/fire cache: a `density` grid and a `temperature` grid on
// DIFFERENT lattices (temperature at twice the voxel size, density shifted by
// half a voxel), temperature in Blender's dimensionless unit (ambient 0, flames
// ~1..1.5) to be mapped to kelvin by the scene's temperature.scale/offset.
//
//   gen_fire_vdb OUT.vdb [--resolution N] [--seed S] [--time T] [--sparse] [--float]
//
// --resolution: density voxels across the 3-unit-wide domain (default 64).
// --time T in [0,1]: the fireball rises, expands and cools as T grows (for
//   animation); default 0.35.
// --sparse: an explosion-like thin noisy shell with empty inside and outside
//   (large empty regions, for majorant-grid tests).
// --float: store 32-bit floats (default: half floats, as Blender and Houdini
//   caches usually are). Compression is blosc (+ active mask) when available.
// Deterministic: the noise is a hash of the integer lattice and the seed, no
// library random number generator is involved.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>

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

// Value noise in [0,1].
double value_noise(double x, double y, double z, uint32_t seed) {
  const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  const int32_t ix = int32_t(fx), iy = int32_t(fy), iz = int32_t(fz);
  const double u = fade(x - fx), v = fade(y - fy), w = fade(z - fz);
  double c[2][2][2];
  for (int a = 0; a < 2; ++a)
    for (int b = 0; b < 2; ++b)
      for (int d = 0; d < 2; ++d) c[a][b][d] = lattice(ix + a, iy + b, iz + d, seed);
  auto lerp = [](double p, double q, double t) { return p + (q - p) * t; };
  return lerp(lerp(lerp(c[0][0][0], c[1][0][0], u), lerp(c[0][1][0], c[1][1][0], u), v),
              lerp(lerp(c[0][0][1], c[1][0][1], u), lerp(c[0][1][1], c[1][1][1], u), v), w);
}

// Fractional Brownian motion: octaves at doubling frequency, halving amplitude; in [0,1].
double fbm(const openvdb::Vec3d& p, uint32_t seed, int octaves = 5) {
  double sum = 0, amp = 0.5, norm = 0, f = 1;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * value_noise(p.x() * f, p.y() * f, p.z() * f, seed + 101u * uint32_t(o));
    norm += amp;
    amp *= 0.5;
    f *= 2.03;  // not exactly 2: keeps octave lattices from lining up
  }
  return sum / norm;
}

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
  bool half = true;
};

// The fields at a world point. Domain: x, z in [-1.5, 1.5], y in [0, 3.5].
struct Fire {
  Params prm;
  openvdb::Vec3d centre;
  double radius, core_heat;

  explicit Fire(const Params& p) : prm(p) {
    const double t = prm.time;
    centre = openvdb::Vec3d(0, 0.9 + 0.5 * t, 0);  // rises
    radius = 0.7 + 0.45 * t;                       // expands
    core_heat = 1.65 - 0.6 * t;                    // cools
  }

  // Turbulent displacement: sample the noise at a warped point (domain warping).
  openvdb::Vec3d warp(const openvdb::Vec3d& p, double amount) const {
    // Two scales of warp: big billows, then finer curls on top.
    const openvdb::Vec3d q = p * 1.1 + openvdb::Vec3d(0, -1.5 * prm.time, 0);
    const openvdb::Vec3d w = p + amount * openvdb::Vec3d(fbm(q, prm.seed + 11, 3) - 0.5,
                                                         fbm(q, prm.seed + 23, 3) - 0.5,
                                                         fbm(q, prm.seed + 37, 3) - 0.5);
    const openvdb::Vec3d q2 = w * 3.1;
    return w + 0.35 * amount * openvdb::Vec3d(fbm(q2, prm.seed + 41, 3) - 0.5, fbm(q2, prm.seed + 43, 3) - 0.5,
                                              fbm(q2, prm.seed + 47, 3) - 0.5);
  }

  double density(const openvdb::Vec3d& p0) const {
    const openvdb::Vec3d p = warp(p0, 0.8);
    const double detail = fbm(p * 2.4, prm.seed + 1);
    const double r = (p - centre).length() / radius;
    if (prm.sparse) {
      // Explosion shell: a noisy band around r = 1, nothing inside or outside.
      const double band = std::abs(r - 1.0 + 0.25 * (detail - 0.5));
      return 1.4 * smoothstep(0.14, 0.03, band) * smoothstep(0.3, 0.55, detail);
    }
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
    const openvdb::Vec3d p = warp(p0, 0.7);
    const double r = (p - centre).length() / radius;
    const double n = fbm(p * 2.0, prm.seed + 3);
    if (prm.sparse) {
      const double band = std::abs(r - 0.95 + 0.25 * (n - 0.5));
      return core_heat * smoothstep(0.16, 0.02, band);
    }
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

// Evaluates f at every voxel centre of the grid's index box; keeps voxels above
// `threshold` active (a sparse tree, as simulators write).
template <class F>
openvdb::FloatGrid::Ptr make_grid(const std::string& name, double voxel, const openvdb::Vec3d& offset,
                                  const openvdb::Vec3d& lo, const openvdb::Vec3d& hi, double threshold, bool half,
                                  F f) {
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(name);
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  grid->setSaveFloatAsHalf(half);
  auto xf = openvdb::math::Transform::createLinearTransform(voxel);
  xf->postTranslate(offset);
  grid->setTransform(xf);
  // Voxel ijk's value is the field at index point ijk (cell-centred), i.e.
  // world = voxel * ijk + offset.
  const openvdb::Coord a = openvdb::Coord::floor(xf->worldToIndex(lo)), b = openvdb::Coord::ceil(xf->worldToIndex(hi));
  auto acc = grid->getAccessor();
  for (int k = a.z(); k <= b.z(); ++k)
    for (int j = a.y(); j <= b.y(); ++j)
      for (int i = a.x(); i <= b.x(); ++i) {
        const openvdb::Coord ijk(i, j, k);
        const double v = f(xf->indexToWorld(ijk));
        if (v > threshold) acc.setValue(ijk, float(v));
      }
  grid->pruneGrid();
  return grid;
}

// To stderr with status 2 for a bad command line; to stdout with 0 for --help.
int usage(bool asked = false) {
  (asked ? std::cout : std::cerr) << "usage: gen_fire_vdb OUT.vdb [--resolution N] [--seed S] [--time T] [--sparse] [--float]\n";
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
    else if (a == "--float") prm.half = false;
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

  openvdb::initialize();
  const Fire fire(prm);
  const openvdb::Vec3d lo(-1.5, 0.0, -1.5), hi(1.5, 3.5, 1.5);
  const double h = (hi.x() - lo.x()) / prm.resolution;
  // Like a Blender export: density at voxel h with its lattice shifted by half
  // a voxel; temperature at 2h, unshifted. No sample point is shared.
  auto density = make_grid("density", h, openvdb::Vec3d(0.5 * h), lo, hi, 2e-3, prm.half,
                           [&](const openvdb::Vec3d& p) { return fire.density(p); });
  auto temperature = make_grid("temperature", 2 * h, openvdb::Vec3d(0.0), lo, hi, 1e-2, prm.half,
                               [&](const openvdb::Vec3d& p) { return fire.temperature(p); });

  openvdb::io::File file(out);
  file.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
  openvdb::MetaMap meta;
  meta.insertMeta("creator", openvdb::StringMetadata("pyrolume/gen_fire_vdb"));
  meta.insertMeta("pyrolume/seed", openvdb::Int32Metadata(int32_t(prm.seed)));
  meta.insertMeta("pyrolume/resolution", openvdb::Int32Metadata(prm.resolution));
  meta.insertMeta("pyrolume/time", openvdb::DoubleMetadata(prm.time));
  meta.insertMeta("pyrolume/variant", openvdb::StringMetadata(prm.sparse ? "sparse shell" : "fireball"));
  meta.insertMeta("pyrolume/temperature_unit",
                  openvdb::StringMetadata("dimensionless (Blender-like): 0 ambient, ~1.5 hottest; map with "
                                          "temperature.scale/offset"));
  try {
    file.write({density, temperature}, meta);
    file.close();
  } catch (const openvdb::Exception& e) {
    std::cerr << out << ": cannot write: " << e.what() << "\n";
    return 1;
  }
  std::printf("%s: density %llu active voxels (voxel %.4g), temperature %llu active voxels (voxel %.4g)\n",
              out.c_str(), (unsigned long long)density->activeVoxelCount(), h,
              (unsigned long long)temperature->activeVoxelCount(), 2 * h);
  return 0;
}
