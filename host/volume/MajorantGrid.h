#pragma once
// A coarse grid of conservative density bounds over a dense texture, for delta
// tracking with per-cell majorants (pbrt-v4's MajorantGrid, traversed by 3D DDA).
#include <vector>

#include <glm/glm.hpp>

#include "volume/DenseGrid.h"

namespace pyrolume {

struct MajorantGrid {
  glm::ivec3 res{1};          // cells per axis
  glm::dvec3 cell_size{1.0};  // in texels: cell c spans texel coords [c·size, (c+1)·size)
  std::vector<float> max_density;  // per cell, x fastest

  float at(int x, int y, int z) const { return max_density[(size_t(z) * res.y + y) * res.x + x]; }
};

// About one cell per 16³ texels, at most 64 per axis (pbrt-v4 uses 16³ cells
// over a grid; finer cells skip more empty space but cost more DDA steps).
glm::ivec3 default_majorant_resolution(glm::ivec3 dims);

// Each cell holds the max of every stored texel whose trilinear footprint reaches
// into the cell. Texel centres sit at texel coords i + 0.5, so a lookup at u
// blends texels floor(u − 0.5) and floor(u − 0.5) + 1: a cell [a, b) needs texels
// floor(a − 0.5) … floor(b − 0.5) + 1. Trilinear interpolation is a convex
// combination, so no lookup inside the cell can exceed that max, whatever
// precision the hardware uses for its weights.
MajorantGrid build_majorant_grid(const DenseGrid& density, glm::ivec3 res);

}  // namespace pyrolume
