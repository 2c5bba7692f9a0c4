#include "volume/MajorantGrid.h"

#include <algorithm>
#include <cmath>

namespace pyrolume {

glm::ivec3 default_majorant_resolution(glm::ivec3 dims) {
  glm::ivec3 r;
  for (int a = 0; a < 3; ++a) r[a] = std::clamp((dims[a] + 15) / 16, 1, 64);
  return r;
}

MajorantGrid build_majorant_grid(const DenseGrid& g, glm::ivec3 res) {
  MajorantGrid m;
  m.res = glm::max(res, glm::ivec3(1));
  m.cell_size = glm::dvec3(g.dims) / glm::dvec3(m.res);
  m.max_density.assign(size_t(m.res.x) * m.res.y * m.res.z, 0.0f);
  if (g.empty()) return m;
  // Texel range [lo, hi] of each cell along one axis.
  auto range = [&](int axis, int c, int& lo, int& hi) {
    double a = c * m.cell_size[axis], b = (c + 1) * m.cell_size[axis];
    lo = std::max(0, int(std::floor(a - 0.5)));
    hi = std::min(g.dims[axis] - 1, int(std::floor(b - 0.5)) + 1);
  };
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

}  // namespace pyrolume
