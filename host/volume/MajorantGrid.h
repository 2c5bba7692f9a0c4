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

// The majorant grid is a trade: finer cells bound the density more tightly
// (fewer tentative collisions, each a density lookup) but a ray crosses more
// of them. What a ray costs, in density lookups, for a candidate grid: delta
// tracking of kCostRays random rays (a uniform random line through the
// texture, from where it enters; isotropic in world space), each continuing
// after a real collision with probability `albedo` (up to kCostBounces times)
// in a new isotropic direction. A cell crossing costs what CellCosts says,
// which depends on how the GPU tracks (docs/benchmarks.md "Choosing the
// majorant grid's cells"). A ray stops counting at kCostCapPerRay: in a
// nearly opaque medium every candidate pays thousands of lookups per ray to
// cross the one texel where the density ramps up, and simulating them all
// would cost seconds to learn nothing (the cells then decide, and the
// coarsest wins). Deterministic: a fixed random sequence.
struct CellCosts {
  double cell, empty;  // entering a non-empty / an empty cell, in density lookups
};
// Scenes with more than one medium: every crossing of a non-empty cell is one
// more pass of the free-flight loop, which costs about what a lookup does on
// lavapipe; a run of empty cells is walked in one pass (grid_majorant).
inline constexpr CellCosts kRestartedFlightCosts{1.0, 0.05};
// A grid that is the scene's only medium: a free flight walks the cells with
// one sampled optical depth (grid_free_flight), each cell, empty or not, one
// DDA step.
inline constexpr CellCosts kWalkedFlightCosts{0.25, 0.25};
inline constexpr int kCostRays = 2048, kCostBounces = 8;
inline constexpr double kCostCapPerRay = 128.0;
double tracking_cost(const DenseGrid& density, const MajorantGrid& m, double sigma_t_per_density, double albedo,
                     CellCosts costs = kRestartedFlightCosts);

// The cheapest of the resolutions ceil(dims/16)·2^j, j = 0..3 (16, 8, 4 and 2
// texels per cell, while the grid stays within kMaxMajorantCells) by
// tracking_cost; the coarsest, default_majorant_resolution, on ties. Each is
// the next one's cells max-pooled 2×2×2, which is exactly the grid
// build_majorant_grid makes at that resolution.
inline constexpr size_t kMaxMajorantCells = size_t(1) << 21;
glm::ivec3 choose_majorant_resolution(const DenseGrid& density, double sigma_t_per_density, double albedo,
                                      CellCosts costs = kRestartedFlightCosts);

}  // namespace pyrolume
