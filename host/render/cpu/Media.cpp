#include "render/cpu/Media.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "color/Blackbody.h"
#include "color/EmissionModel.h"
#include "render/cpu/Intersect.h"
#include "scene/MediumVolume.h"

namespace pyrolume::cpu {

namespace {

MediumData prepare_homogeneous(const Medium& m) {
  MediumData d;
  d.type = m.type;
  d.name = m.name;
  d.bounds = m.bounds;
  d.sigma_a = m.sigma_a;
  d.sigma_s = m.sigma_s;
  d.sigma_maj = m.sigma_a + m.sigma_s;
  d.g = m.g;
  glm::dvec3 Le(0.0);
  if (m.emission.emits()) {
    if (m.emission.rgb)
      Le = m.emission.scale * *m.emission.rgb;
    else if (m.emission.temperature_k)
      Le = m.emission.scale * color::blackbody_rgb(*m.emission.temperature_k, m.emission.blackbody,
                                                   m.emission.observer, m.emission.adapt_to_k);
  }
  d.sigma_a_Le = m.sigma_a * Le;
  return d;
}

MediumData prepare_vdb(const Medium& m, std::vector<std::string>& warnings) {
  MediumData d;
  d.type = m.type;
  d.name = m.name;
  d.g = m.g;
  d.sigma_a = m.sigma_a * m.density_scale;
  d.sigma_s = m.sigma_s * m.density_scale;
  auto vol = std::make_shared<StoredVolume>(load_stored_volume(m));
  for (const std::string& w : vol->warnings) warnings.push_back(w);
  // The bound comes from the texels themselves (not the loader's max_value), so
  // it holds for exactly what is sampled. NaN texels would break it: the loader
  // turns them into 0; skip them here too so they cannot poison the bound.
  const double max_rho = vol->density.grid.max_texel();
  d.max_density = max_rho;
  d.sigma_maj = (d.sigma_a + d.sigma_s) * max_rho;
  d.temperature = m.temperature;
  d.emission = m.emission;
  if (m.emission.emits() && m.emission.rgb) {
    d.emits_rgb = true;
    d.Le_rgb = m.emission.scale * *m.emission.rgb;
  } else if (needs_temperature_grid(m) && vol->temperature && !vol->temperature->grid.empty()) {
    d.emits_temperature = true;
  }
  d.volume = std::move(vol);
  return d;
}

}  // namespace

MediaData prepare_media(const Scene& scene) {
  MediaData md;
  for (const Medium& m : scene.media)
    md.media.push_back(m.type == Medium::Type::Vdb ? prepare_vdb(m, md.warnings) : prepare_homogeneous(m));
  return md;
}

void ray_spans(const MediaData& md, const glm::dvec3& o, const glm::dvec3& d, std::vector<Span>& spans,
               std::vector<double>& cuts) {
  spans.clear();
  cuts.clear();
  for (int i = 0; i < int(md.media.size()); ++i) {
    const MediumData& m = md.media[i];
    RayInterval r;
    if (m.is_vdb()) {
      if (!m.volume || m.volume->density.grid.empty() || !(m.max_density > 0.0)) continue;
      const DenseGrid& g = m.volume->density.grid;
      const glm::dvec3 oi(g.world_to_index * glm::dvec4(o, 1.0));
      const glm::dvec3 di(g.world_to_index * glm::dvec4(d, 0.0));
      r = intersect_box(oi, di, glm::dvec3(g.origin), glm::dvec3(g.origin + g.dims - 1));
    } else {
      r = intersect_bounds(o, d, m.bounds);
    }
    if (!r.hit) continue;
    double t0 = std::max(r.t0, 0.0), t1 = r.t1;
    if (!(t1 > t0)) continue;  // behind the origin, tangent, or zero length
    spans.push_back({t0, t1, i});
    cuts.push_back(t0);
    cuts.push_back(t1);
  }
  std::sort(cuts.begin(), cuts.end());
  cuts.erase(std::unique(cuts.begin(), cuts.end()), cuts.end());
}

double media_present(const MediaData& md, const std::vector<Span>& spans, double a, double b, int c,
                     std::vector<int>& present) {
  present.clear();
  double sigma_maj = 0.0;
  // The cuts are the spans' own endpoints, so containment is exact.
  for (const Span& sp : spans)
    if (sp.t0 <= a && sp.t1 >= b) {
      present.push_back(sp.medium);
      sigma_maj += md.media[sp.medium].sigma_maj[c];
    }
  return sigma_maj;
}

double sigma_t_at(const MediaData& md, const std::vector<int>& present, int c, const glm::dvec3& p,
                  uint64_t* lookups) {
  double sigma_t = 0.0;
  for (int i : present) {
    const MediumData& m = md.media[i];
    double k = m.sigma_a[c] + m.sigma_s[c];
    if (m.is_vdb()) {
      k *= grid_density(m, p);
      if (lookups) ++*lookups;
    }
    sigma_t += k;
  }
  return sigma_t;
}

double grid_density(const MediumData& m, const glm::dvec3& p) { return m.volume->density.grid.sample_world(p); }

double grid_temperature_k(const MediumData& m, const glm::dvec3& p) {
  const double v = m.volume->temperature ? m.volume->temperature->grid.sample_world(p) : 0.0;
  return m.temperature.kelvin(v);
}

glm::dvec3 grid_Le_of_temperature(const MediumData& m, double T) {
  return temperature_Le(T, m.temperature.cutoff_k, m.emission.scale, m.emission.blackbody, m.emission.observer,
                        m.emission.adapt_to_k);
}

glm::dvec3 LeCache::get(const MediumData& m, int medium, double T_k) {
  if (int(T.size()) <= medium) {
    T.resize(medium + 1, std::numeric_limits<double>::quiet_NaN());
    Le.resize(medium + 1);
  }
  if (!(T[medium] == T_k)) {  // NaN never matches: recomputed (and 0)
    T[medium] = T_k;
    Le[medium] = grid_Le_of_temperature(m, T_k);
  }
  return Le[medium];
}

double grid_sigma_a_Le(const MediumData& m, int medium, int c, const glm::dvec3& p, double rho, LeCache& cache) {
  const double sigma_a = m.sigma_a[c] * rho;
  if (!(sigma_a > 0.0)) return 0.0;
  if (m.emits_rgb) return sigma_a * m.Le_rgb[c];
  if (m.emits_temperature) return sigma_a * cache.get(m, medium, grid_temperature_k(m, p))[c];
  return 0.0;
}

// The line estimator's second process (walk_channel), this reference's own
// rule, not the GPU's per-cell rates: in a grid medium a point every
// 1/kLinePointsPerVoxel voxels on average, over the whole medium; in a
// homogeneous one kLinePointsPerWidth across its smallest extent.
constexpr double kLinePointsPerVoxel = 0.25, kLinePointsPerWidth = 8.0;
double line_rate(const MediumData& m) {
  if (!m.is_vdb()) {
    const double width = m.bounds.smallest_extent();
    return width > 0.0 ? kLinePointsPerWidth / width : 0.0;
  }
  if (!m.volume || m.volume->density.grid.empty()) return 0.0;
  const glm::dmat4& to_world = m.volume->density.grid.index_to_world;
  const double voxel = std::min({glm::length(glm::dvec3(to_world[0])), glm::length(glm::dvec3(to_world[1])),
                                 glm::length(glm::dvec3(to_world[2]))});
  return voxel > 0.0 ? kLinePointsPerVoxel / voxel : 0.0;
}

}  // namespace pyrolume::cpu
