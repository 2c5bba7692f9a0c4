#include "render/LineEstimator.h"

#include <algorithm>
#include <climits>

#include "color/ColorSpace.h"
#include "light/EmissionCdf.h"
#include "light/LightSelection.h"
#include "scene/MediumVolume.h"
#include "util/Math.h"

namespace pyrolume {

glm::ivec3 majorant_resolution(const Scene& scene, const Medium& m, const DenseGrid& density) {
  const Integrator& in = scene.integrator;
  if (in.majorant == Majorant::Global) return glm::ivec3(1);
  if (in.majorant_grid) return *in.majorant_grid;
  const glm::dvec3 sigma_t = m.sigma_a + m.sigma_s;
  const double albedo = sigma_t.x + sigma_t.y + sigma_t.z > 0.0
                            ? (m.sigma_s.x + m.sigma_s.y + m.sigma_s.z) / (sigma_t.x + sigma_t.y + sigma_t.z)
                            : 0.0;
  // A grid that is the scene's only medium: its free flights walk the cells
  // (shaders/tracking.glsl ONE_GRID), which makes crossing them cheaper.
  const CellCosts costs = scene.media.size() == 1 ? kWalkedFlightCosts : kRestartedFlightCosts;
  return choose_majorant_resolution(density, std::max({sigma_t.x, sigma_t.y, sigma_t.z}) * m.density_scale, albedo,
                                    costs);
}

namespace {
}  // namespace

LineRates line_rates(const Medium& m, const DenseGrid& density, const DenseGrid* temperature, const MajorantGrid& mg) {
  LineRates out;
  const size_t n = size_t(mg.res.x) * size_t(mg.res.y) * size_t(mg.res.z);
  out.rate.assign(n, 0.0f);
  if (!m.emission.emits()) return out;
  // A large sparse grid's weights come in blocks of 8³ cells (EmissionCdf::build_sparse_blocks).
  const glm::ivec3 D = density.dims - 1;
  const bool blocks = density.is_sparse() &&
                      uint64_t(D.x) * uint64_t(D.y) * uint64_t(D.z) > EmissionCdf::kMaxCellsForCellLight;
  const int bs = blocks ? 8 : 1;
  const EmissionCdf cells = blocks
                                ? EmissionCdf::build_sparse_blocks(density, temperature, EmissionParams::from_medium(m), bs)
                                : EmissionCdf::build(density, temperature, EmissionParams::from_medium(m));
  if (cells.empty()) return out;
  out.power = cells.power();

  // E_c: emission cell (i, j, k) spans texel coordinates [i + 0.5, i + 1.5)
  // per axis (EmissionCdf.h; a block of bs cells, [bs·i + 0.5, bs·(i + 1) + 0.5)); it overlaps majorant
  // cells floor(a / size) … ceil(b / size) − 1, clamped to the grid.
  std::vector<double> E(n, 0.0);
  const glm::ivec3 C = cells.cells();
  for (int k = 0; k < C.z; ++k)
    for (int j = 0; j < C.y; ++j)
      for (int i = 0; i < C.x; ++i) {
        const double w = cells.cell_weight({i, j, k});
        if (!(w > 0.0)) continue;
        const glm::dvec3 a = double(bs) * glm::dvec3(i, j, k) + 0.5, b = a + double(bs);
        const glm::ivec3 lo = glm::clamp(glm::ivec3(glm::floor(a / mg.cell_size)), glm::ivec3(0), mg.res - 1);
        const glm::ivec3 hi = glm::clamp(glm::ivec3(glm::ceil(b / mg.cell_size)) - 1, glm::ivec3(0), mg.res - 1);
        for (int z = lo.z; z <= hi.z; ++z)
          for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) {
              double& e = E[(size_t(z) * mg.res.y + y) * mg.res.x + x];
              e = std::max(e, w);
            }
      }

  // World length of a cell edge along each axis (cell_size texels of one voxel each).
  glm::dvec3 edge;
  for (int a = 0; a < 3; ++a) edge[a] = mg.cell_size[a] * glm::length(glm::dvec3(density.index_to_world[a]));
  const double r = kLinePointsPerCell / std::min({edge.x, edge.y, edge.z});
  if (!std::isfinite(r) || !(r > 0.0)) return out;  // a degenerate transform: collisions only
  const double sigma_scale = max3(m.sigma_a + m.sigma_s) * m.density_scale;
  glm::ivec3 lo(INT_MAX), hi(INT_MIN);  // the emissive cells' bounding box
  double weighted = 0.0, total = 0.0;
  for (int z = 0; z < mg.res.z; ++z)
    for (int y = 0; y < mg.res.y; ++y)
      for (int x = 0; x < mg.res.x; ++x) {
        const size_t c = (size_t(z) * mg.res.y + y) * mg.res.x + x;
        if (!(E[c] > 0.0)) continue;
        out.rate[c] = float(r);
        lo = glm::min(lo, glm::ivec3(x, y, z));
        hi = glm::max(hi, glm::ivec3(x, y, z));
        weighted += E[c] * double(mg.max_density[c]) * sigma_scale;
        total += E[c];
      }
  if (!(total > 0.0)) return out;
  const glm::dvec3 across = glm::dvec3(hi - lo + 1) * edge;
  out.collisions_across = weighted / total * std::min({across.x, across.y, across.z});
  return out;
}

bool homogeneous_emission_is_thin(const Medium& m) {
  if (m.type != Medium::Type::Homogeneous || !m.emission.emits() || !(max3(m.sigma_a) > 0.0)) return false;
  return max3(m.sigma_a + m.sigma_s) * m.bounds.smallest_extent() < kThinCollisionsAcross;
}

LineMedia line_media(const Scene& scene, const std::vector<const StoredVolume*>& volumes) {
  const size_t n = scene.media.size();
  const LineMediaRule rule = line_media_rule(scene.integrator);
  const bool every = rule == LineMediaRule::EveryEmitting;
  LineMedia out;
  out.line.assign(n, false);
  out.rates.resize(n);
  out.majorant_res.assign(n, glm::ivec3(0));
  if (rule == LineMediaRule::None) return out;
  std::vector<double> power(n, 0.0);
  double total = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const Medium& m = scene.media[i];
    if (!m.emission.emits()) continue;
    if (m.type == Medium::Type::Homogeneous) {
      power[i] = color::srgb_luminance(m.sigma_a * homogeneous_le(m.emission)) * m.bounds.volume();
      out.line[i] = every || homogeneous_emission_is_thin(m);
    } else {
      const StoredVolume* vol = i < volumes.size() ? volumes[i] : nullptr;
      if (!vol || vol->density.grid.empty()) continue;
      const DenseGrid& density = vol->density.grid;
      const DenseGrid* temperature =
          vol->temperature && !vol->temperature->grid.empty() ? &vol->temperature->grid : nullptr;
      out.majorant_res[i] = majorant_resolution(scene, m, density);
      LineRates rates = line_rates(m, density, temperature, build_majorant_grid(density, out.majorant_res[i]));
      power[i] = rates.power;
      out.line[i] = every || rates.thin();
      out.rates[i] = std::move(rates.rate);
    }
    total += std::max(0.0, power[i]);
  }
  for (size_t i = 0; i < n; ++i) {
    if (rule == LineMediaRule::Thin) out.line[i] = out.line[i] && power[i] >= kLineMinPowerShare * total;
    if (!out.line[i]) out.rates[i].clear();
  }
  return out;
}

}  // namespace pyrolume
