#pragma once
// The scene's media as the CPU reference sees them: homogeneous media (sphere /
// box bounds, constant coefficients) and grid (`vdb`) media whose density and
// temperature are looked up trilinearly in the grids AS STORED for the GPU
// (StoredVolume: R16F-rounded values, one texture per grid with its own
// transform), so both backends render the same field.
//
// Grid medium at x (docs/scene-format.md "media"):
//   σa(x) = sigma_a · density_scale · ρ(x),  σs(x) = sigma_s · density_scale · ρ(x),
//   emitted radiance per unit length σa(x) · Le(x), with
//   Le(x) = emission.scale · blackbody(T(x)),  T(x) = (temperature(x) − offset) · scale,
//   and Le = 0 where T <= cutoff_k; or Le = emission.scale · rgb everywhere when the
//   medium gives emission.rgb. ρ and the temperature value are 0 outside their
//   grids' dense boxes (the background), so outside the temperature grid
//   T = −offset · scale.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/Scene.h"
#include "volume/StoredVolume.h"

namespace pyrolume::cpu {

struct MediumData {
  Medium::Type type = Medium::Type::Homogeneous;
  std::string name;
  double g = 0.0;
  // Homogeneous: the coefficients. Vdb: per unit stored density, i.e. already
  // multiplied by density_scale.
  glm::dvec3 sigma_a{0.0}, sigma_s{0.0};
  // Majorant of σt = σa + σs per channel over the medium's extent: σt itself
  // for a homogeneous medium; (σa + σs) · max stored density for a grid
  // (trilinear weights are a convex combination, so no lookup exceeds the
  // largest texel).
  glm::dvec3 sigma_maj{0.0};

  // Homogeneous only.
  Bounds bounds;
  glm::dvec3 sigma_a_Le{0.0};  // emitted radiance per unit length, σa · Le

  // Vdb only. Absent/empty density: the medium has no extent.
  std::shared_ptr<const StoredVolume> volume;
  double max_density = 0.0;       // largest stored density texel
  bool emits_rgb = false;         // Le = Le_rgb everywhere
  glm::dvec3 Le_rgb{0.0};
  bool emits_temperature = false;  // Le from the temperature grid
  TemperatureMapping temperature;
  Emission emission;
  // With the line estimator (docs/rendering.md "Emission estimators"): the
  // rate, per unit length, of the points at which the walk collects this
  // medium's emission besides its tentative collisions; 0: collisions only.
  double line_rate = 0.0;

  bool is_vdb() const { return type == Medium::Type::Vdb; }
};

struct MediaData {
  std::vector<MediumData> media;
  std::vector<std::string> warnings;  // the loader's, one line each
};

// Loads every vdb medium's grids (load_stored_volume; throws its InputError).
MediaData prepare_media(const Scene& scene);

// A medium's extent along the ray o + t·d, clipped to t >= 0.
struct Span {
  double t0, t1;
  int medium;
};

// Spans of every medium the ray passes through (any order) and the sorted,
// unique list of their endpoints ("cuts"): between two consecutive cuts the set
// of media present is constant. A vdb medium's extent is its density texture's
// support, the padded texel box in index space (origin .. origin + dims − 1):
// the ray is mapped by world_to_index and clipped there; the map is affine, so
// the ray parameter t is the same in both spaces.
void ray_spans(const MediaData& md, const glm::dvec3& o, const glm::dvec3& d, std::vector<Span>& spans,
               std::vector<double>& cuts);

// The media whose spans cover [a, b] (a, b consecutive cuts), and the segment's
// majorant for channel c: the sum of those media's global majorants. With one
// medium this is that medium's single global majorant; overlapping media add.
double media_present(const MediaData& md, const std::vector<Span>& spans, double a, double b, int c,
                     std::vector<int>& present);

// σt_c(p) summed over the `present` media; adds the number of density-texture
// lookups made (one per vdb medium) to *lookups.
double sigma_t_at(const MediaData& md, const std::vector<int>& present, int c, const glm::dvec3& p,
                  uint64_t* lookups);

// A tentative collision found σt(x) > σ̄, i.e. a negative null-collision
// probability. Relative slack for the rounding of a convex combination.
inline bool exceeds_majorant(double sigma_t, double sigma_maj) { return sigma_t > sigma_maj * (1.0 + 1e-9); }

// Stored density ρ(p) of a vdb medium (trilinear, 0 outside; no density_scale).
double grid_density(const MediumData& m, const glm::dvec3& p);

// Temperature in kelvin at p: (value − offset) · scale (value 0 outside the grid).
double grid_temperature_k(const MediumData& m, const glm::dvec3& p);

// Le of a vdb medium at temperature T, what the GPU LUT returns: the emission
// rule of color/EmissionModel.h (temperature_Le), Planck evaluated directly.
glm::dvec3 grid_Le_of_temperature(const MediumData& m, double T);

// One-entry memo of grid_Le_of_temperature per medium (exact: same T, same Le).
// Constant temperature regions then cost one blackbody evaluation per walk.
struct LeCache {
  std::vector<double> T;
  std::vector<glm::dvec3> Le;
  glm::dvec3 get(const MediumData& m, int medium, double T_k);
};

// Emitted radiance of vdb medium m at p, channel c, per unit length:
// σa_c(p) · Le_c(p), given the density rho already looked up at p.
double grid_sigma_a_Le(const MediumData& m, int medium, int c, const glm::dvec3& p, double rho, LeCache& cache);

// The line estimator's rate of collection points in medium m, per unit
// length (MediumData::line_rate; this reference's own rule, not the GPU's
// per-cell rates: Media.cpp).
double line_rate(const MediumData& m);

}  // namespace pyrolume::cpu
