#include "geometry/Terrain.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <glm/glm.hpp>
#include <vector>

namespace pyrolume::geometry {
namespace {

// Integer hash (PCG output permutation; Jarzynski & Olano 2020) → [0, 1).
double lattice(uint32_t seed, int32_t x, int32_t z) {
  uint32_t v = seed * 747796405u + uint32_t(x) * 2891336453u + uint32_t(z) * 1181783497u + 2891336453u;
  v = v * 747796405u + 2891336453u;
  uint32_t w = ((v >> ((v >> 28u) + 4u)) ^ v) * 277803737u;
  w = (w >> 22u) ^ w;
  return double(w) / 4294967296.0;
}

// Value noise in [−1, 1] with quintic fade (C², so normals are smooth).
double value_noise(uint32_t seed, double x, double z) {
  const double fx = std::floor(x), fz = std::floor(z);
  const int32_t ix = int32_t(fx), iz = int32_t(fz);
  auto fade = [](double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); };
  const double sx = fade(x - fx), sz = fade(z - fz);
  const double a = lattice(seed, ix, iz), b = lattice(seed, ix + 1, iz);
  const double c = lattice(seed, ix, iz + 1), d = lattice(seed, ix + 1, iz + 1);
  return 2.0 * ((a + (b - a) * sx) * (1.0 - sz) + (c + (d - c) * sx) * sz) - 1.0;
}

// fBm: octaves of noise, each twice the frequency and half the amplitude;
// normalised to [−1, 1].
double fbm(uint32_t seed, double x, double z, int octaves) {
  double sum = 0.0, amp = 1.0, norm = 0.0, freq = 1.0;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * value_noise(seed + uint32_t(o) * 1013u, x * freq, z * freq);
    norm += amp;
    amp *= 0.5;
    freq *= 2.03;  // not exactly 2: lattice lines of octaves do not line up
  }
  return sum / norm;
}

double max_raw_height(const TerrainParams& p) {
  double m = 0.0;
  for (int j = 0; j < p.grid; ++j)
    for (int i = 0; i < p.grid; ++i) {
      const double x = -0.5 * p.width + p.width * i / (p.grid - 1);
      const double z = -0.5 * p.width + p.width * j / (p.grid - 1);
      m = std::max(m, terrain_height_raw(p, x, z));
    }
  return m;
}

glm::dvec3 terrain_normal(const TerrainParams& p, double scale, double x, double z) {
  const double h = p.width / (p.grid - 1);
  const double dx = (terrain_height_raw(p, x + h, z) - terrain_height_raw(p, x - h, z)) * scale / (2.0 * h);
  const double dz = (terrain_height_raw(p, x, z + h) - terrain_height_raw(p, x, z - h)) * scale / (2.0 * h);
  return glm::normalize(glm::dvec3(-dx, 1.0, -dz));
}

}  // namespace

double terrain_height_raw(const TerrainParams& p, double x, double z) {
  // Gaussian envelope (a single massif, ~0 at the rim), modulated by large-
  // scale fBm for the shape and a ridged octave stack for rocky detail.
  const double s = p.width / 20.0;  // the constants below are for a 20-unit-wide mountain
  const double r2 = (x * x + z * z) / (s * s);
  const double envelope = std::exp(-r2 / (2.0 * 3.6 * 3.6));
  const double shape = fbm(p.seed, x / (6.0 * s), z / (6.0 * s), 3);
  const double ridged = 1.0 - std::fabs(fbm(p.seed ^ 0x9e3779b9u, x / (2.5 * s), z / (2.5 * s), 5));
  return envelope * (0.75 + 0.35 * shape + 0.25 * ridged) + 0.02 * envelope * fbm(p.seed + 77u, x / s, z / s, 3);
}

std::string terrain_obj(const TerrainParams& p) {
  const double scale = p.peak / max_raw_height(p);
  const int n = p.grid;
  std::string out;
  out.reserve(size_t(n) * size_t(n) * 120);
  char line[160];
  std::snprintf(line, sizeof line,
                "# pyrolume procedural mountain: tools/gen_terrain --seed %u --grid %d (docs/surfaces.md)\n", p.seed,
                n);
  out += line;
  auto coord = [&](int i) { return -0.5 * p.width + p.width * i / (n - 1); };
  auto fix = [](double v) { return std::fabs(v) < 5e-5 ? 0.0 : v; };  // no "-0.0000"
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = coord(i), z = coord(j);
      std::snprintf(line, sizeof line, "v %.4f %.4f %.4f\n", fix(x), fix(terrain_height_raw(p, x, z) * scale), fix(z));
      out += line;
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      std::snprintf(line, sizeof line, "vt %.4f %.4f\n", double(i) / (n - 1), double(j) / (n - 1));
      out += line;
    }
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const glm::dvec3 nn = terrain_normal(p, scale, coord(i), coord(j));
      std::snprintf(line, sizeof line, "vn %.4f %.4f %.4f\n", fix(nn.x), fix(nn.y), fix(nn.z));
      out += line;
    }
  auto id = [&](int i, int j) { return j * n + i + 1; };
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      // Counter-clockwise seen from +y: cross(e1, e2) points up.
      const int a = id(i, j), b = id(i, j + 1), c = id(i + 1, j), d = id(i + 1, j + 1);
      std::snprintf(line, sizeof line, "f %d/%d/%d %d/%d/%d %d/%d/%d\n", a, a, a, b, b, b, c, c, c);
      out += line;
      std::snprintf(line, sizeof line, "f %d/%d/%d %d/%d/%d %d/%d/%d\n", c, c, c, b, b, b, d, d, d);
      out += line;
    }
  return out;
}

Image terrain_albedo(const TerrainParams& p) {
  const double scale = p.peak / max_raw_height(p);
  const int size = p.texture_size;
  Image img = make_image(size, size);
  // Linear albedos, each with red ≤ 0.45·green: the mix of any of them keeps it.
  const glm::dvec3 grass(0.040, 0.105, 0.045), rock(0.085, 0.195, 0.235), pale(0.22, 0.50, 0.58);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      // Texel centre → uv (v = 0 at the image bottom) → world x, z.
      const double u = (x + 0.5) / size, v = 1.0 - (y + 0.5) / size;
      const double wx = -0.5 * p.width + p.width * u, wz = -0.5 * p.width + p.width * v;
      const double h = terrain_height_raw(p, wx, wz) * scale / p.peak;  // 0..1
      const double slope = 1.0 - terrain_normal(p, scale, wx, wz).y;    // 0 flat
      const double jitter = fbm(p.seed + 555u, wx * 1.7, wz * 1.7, 4);  // patches
      double rockiness = std::clamp((slope - 0.08) * 6.0 + 0.6 * h + 0.25 * jitter, 0.0, 1.0);
      double paleness = std::clamp((h - 0.72) * 4.0 + 0.3 * jitter, 0.0, 1.0);
      glm::dvec3 c = glm::mix(grass, rock, rockiness);
      c = glm::mix(c, pale, paleness * rockiness);
      const double grain = 0.85 + 0.3 * (0.5 + 0.5 * fbm(p.seed + 999u, wx * 9.0, wz * 9.0, 3));
      c *= grain;  // a common factor keeps red/green
      for (int k = 0; k < 3; ++k) img.at(x, y, k) = float(c[k]);
    }
  return img;
}

}  // namespace pyrolume::geometry
