#pragma once
// The line emission estimator's rates (docs/rendering.md "The line
// estimator"). The collision estimator collects emission at the tentative
// collisions, a Poisson process of rate σ̄ (the density majorant): in a thin
// medium they are rare, and the emission a ray crosses is estimated from a
// handful of them. The line estimator collects at a Poisson process of rate
// max(σ̄, r) instead, r = kLinePointsPerCell per majorant-cell width in every
// cell that can emit: each ray's emission integral then gets at least
// kLinePointsPerCell points per cell width it crosses, wherever it emits, so
// its relative variance is about the same along every ray.
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/glm.hpp>

#include "scene/Scene.h"
#include "volume/DenseGrid.h"
#include "volume/MajorantGrid.h"
#include "volume/StoredVolume.h"

namespace pyrolume {

// Collection points per majorant-cell width (tools/bench: 4 and 8 tie at
// equal time on the thin Blender fire; 2 is 1.3× worse).
inline constexpr double kLinePointsPerCell = 4.0;
// A medium's emission is thin when a ray across its emission meets fewer
// tentative collisions than this (tools/bench: the line estimator wins at
// equal time on the Blender fire at 0.12 and 1.2 collisions across, loses at 6).
inline constexpr double kThinCollisionsAcross = 2.0;
// "auto" collects a thin medium's emission with the line estimator where it
// gives at least this share of all the media's emitted power: a faint thin
// haze beside a bright fire is not worth its extra points.
inline constexpr double kLineMinPowerShare = 0.25;

struct LineRates {
  // Per majorant cell (x fastest), points per unit world length: r above where
  // the cell can emit, else 0.
  std::vector<float> rate;
  // The tentative collisions a ray meets across the emission: the majorant
  // averaged over the cells that can emit, weighted by their emission bound,
  // times the shortest side of their bounding box (∞ without emission).
  double collisions_across = INFINITY;
  double power = 0.0;  // the emission bound's integral (EmissionCdf::power)
  bool thin() const { return collisions_across < kThinCollisionsAcross; }
};

// For a grid medium with its stored grids (temperature may be null) and its
// density majorant cells (build_majorant_grid). A cell can emit where one of
// the emission cells overlapping it has an emission bound > 0 (EmissionCdf's
// cell weight, Y(σa·Le)), which is also the weight above.
LineRates line_rates(const Medium& m, const DenseGrid& density, const DenseGrid* temperature, const MajorantGrid& mg);

// The majorant grid's resolution for medium m's density texture: one cell
// with integrator.majorant "global", else integrator.majorant_grid, else the
// cheapest for tracking (choose_majorant_resolution, with m's σt per unit
// density and its albedo, and the cell costs of the way the scene's free
// flights cross cells).
glm::ivec3 majorant_resolution(const Scene& scene, const Medium& m, const DenseGrid& density);

// A homogeneous medium (constant emission) is one cell: each ray gets
// kLinePointsPerCell points along its chord through it (shaders/majorant_walk.glsl
// majorant_at). Its emission is thin where it emits and σt times its
// Bounds::smallest_extent is below kThinCollisionsAcross.
bool homogeneous_emission_is_thin(const Medium& m);

struct LineMedia {
  // Per scene medium, whether the line estimator collects its emission.
  std::vector<bool> line;
  // Per scene medium: a grid medium's LineRates::rate where `line` holds
  // (on the majorant grid the GPU builds: majorant_resolution), else empty.
  std::vector<std::vector<float>> rates;
  // Per scene medium: the majorant grid resolution majorant_resolution chose
  // for a grid medium whose rates were computed (0 where none was chosen), so
  // that the renderer does not run the choice's simulation again.
  std::vector<glm::ivec3> majorant_res;
  bool any() const { return std::find(line.begin(), line.end(), true) != line.end(); }
};

// Which media the line estimator collects, by line_media_rule
// (host/light/LightSelection.h, where the estimator is chosen): every
// emitting medium where the file asks for "line"; with "auto", the media
// whose emission is thin and that give at least kLineMinPowerShare of the
// emitted power (Y(σa·Le) over the medium's volume; for grids the emission
// bound's integral). volumes[i]: medium i's grids (null for homogeneous
// media). The render's estimator is "line" where any medium is
// (choose_emission_estimator).
LineMedia line_media(const Scene& scene, const std::vector<const StoredVolume*>& volumes);

}  // namespace pyrolume
