#include "volume/DenseGrid.h"

#include <cmath>
#include <limits>

#include "volume/SparseGrid.h"

namespace pyrolume {

float DenseGrid::sparse_texel(int i, int j, int k) const { return sparse->value(origin + glm::ivec3(i, j, k)); }

double DenseGrid::sample_index(const glm::dvec3& index_pos) const {
  if (sparse) return sparse->sample_index(index_pos);
  if (values.empty()) return 0.0;
  // A sampler3D puts texel t's centre at normalised (t + 0.5) / dims; with
  // u = (index_pos - origin + 0.5) / dims the lookup reduces to this: the
  // texel whose index coordinate is origin + t holds voxel (origin + t).
  const glm::dvec3 x = index_pos - glm::dvec3(origin);
  const glm::dvec3 x0 = glm::floor(x);
  // Far outside: no texel contributes (also guards the int conversion).
  for (int a = 0; a < 3; ++a)
    if (!(x0[a] >= -1.0 && x0[a] < double(dims[a]))) return 0.0;
  const glm::ivec3 i0(x0);
  const glm::dvec3 f = x - x0;
  auto at = [&](int i, int j, int k) -> double {
    // Texels beyond the array are the background (0), like the zero padding.
    if (i < 0 || j < 0 || k < 0 || i >= dims.x || j >= dims.y || k >= dims.z) return 0.0;
    return texel(i, j, k);
  };
  double v = 0.0;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        double w = (dx ? f.x : 1.0 - f.x) * (dy ? f.y : 1.0 - f.y) * (dz ? f.z : 1.0 - f.z);
        if (w != 0.0) v += w * at(i0.x + dx, i0.y + dy, i0.z + dz);
      }
  return v;
}

double DenseGrid::max_texel() const {
  double m = 0.0;
  if (sparse) return max_value > 0.0f ? double(max_value) : 0.0;  // exact: the tree holds floats
  for (float v : values)
    if (v > m) m = v;
  return m;
}

double DenseGrid::sample_world(const glm::dvec3& p) const {
  return sample_index(glm::dvec3(world_to_index * glm::dvec4(p, 1.0)));
}

void DenseGrid::world_bounds(glm::dvec3& lo, glm::dvec3& hi) const {
  lo = glm::dvec3(std::numeric_limits<double>::infinity());
  hi = -lo;
  if (empty()) return;
  // Trilinear support is the open box between the outermost (zero) padding
  // texel centres: index origin .. origin + dims - 1. Map its 8 corners, since
  // the affine map may rotate or shear.
  const glm::dvec3 a(origin), b = glm::dvec3(origin + dims - 1);
  for (int c = 0; c < 8; ++c) {
    glm::dvec3 q((c & 1) ? b.x : a.x, (c & 2) ? b.y : a.y, (c & 4) ? b.z : a.z);
    glm::dvec3 w(index_to_world * glm::dvec4(q, 1.0));
    lo = glm::min(lo, w);
    hi = glm::max(hi, w);
  }
}

size_t dense_bytes(const DenseGrid& g, bool half) { return g.texel_count() * (half ? 2 : 4); }

}  // namespace pyrolume
