#include "scene/MediumVolume.h"

#include <glm/gtc/matrix_transform.hpp>

#include "color/Blackbody.h"

namespace pyrolume {

glm::dvec3 homogeneous_le(const Emission& e) {
  if (e.rgb) return *e.rgb * e.scale;
  if (e.temperature_k) return color::blackbody_rgb(*e.temperature_k, e.blackbody, e.observer, e.adapt_to_k) * e.scale;
  return glm::dvec3(0.0);
}

glm::dmat4 medium_transform_matrix(const Transform& t) {
  glm::dmat4 M(1.0);
  M = glm::translate(M, t.translate);
  M = glm::rotate(M, glm::radians(t.rotate_deg.z), glm::dvec3(0, 0, 1));
  M = glm::rotate(M, glm::radians(t.rotate_deg.y), glm::dvec3(0, 1, 0));
  M = glm::rotate(M, glm::radians(t.rotate_deg.x), glm::dvec3(1, 0, 0));
  M = glm::scale(M, t.scale);
  return M;  // = T * Rz * Ry * Rx * S
}

bool needs_temperature_grid(const Medium& m) {
  return m.type == Medium::Type::Vdb && m.emission.is_grid && m.emission.scale > 0.0;
}

VolumeOptions volume_options(const Medium& m, bool need_temperature) {
  VolumeOptions o;
  o.file = m.file;
  o.density_grid = m.density_grid;
  o.temperature_grid = m.temperature_grid;
  o.need_temperature = need_temperature;
  o.transform = medium_transform_matrix(m.transform);
  o.index_offset = m.index_offset;
  o.downsample = m.downsample;
  o.texture_format = m.texture_format;
  o.temperature = m.temperature;
  return o;
}

VolumeGrids load_volume(const Medium& m, bool need_temperature, const DenseLimits& limits) {
  return load_volume(volume_options(m, need_temperature), limits);
}

StoredVolume load_stored_volume(const Medium& m, const DenseLimits& limits) {
  return load_stored_volume(volume_options(m, needs_temperature_grid(m)), limits);
}

void apply_source_convention(Medium& m, const SourceConvention& c) {
  if (m.density_grid.empty()) m.density_grid = c.density_grid;
  if (m.temperature_grid.empty()) m.temperature_grid = c.temperature_grid;
  if (!m.given.temperature_scale) m.temperature.scale = c.mapping.scale;
  if (!m.given.temperature_offset) m.temperature.offset = c.mapping.offset;
  if (!m.given.temperature_cutoff) m.temperature.cutoff_k = c.mapping.cutoff_k;
  m.index_offset = c.index_offset;
  // The scene asks for emission by writing an emission block or any key of
  // the temperature (docs/sources.md "Smoke is smoke").
  const bool asked = m.given.emission || m.given.temperature_grid || m.given.temperature_scale ||
                     m.given.temperature_offset || m.given.temperature_cutoff;
  if (c.temperature_grid.empty() && !m.given.emission) m.emission.is_grid = false;
  else if (!c.emits && !asked) m.emission.is_grid = false;
  // Smoke that does not glow is shaded as the tool's default volume material:
  // its albedo splits σt = density_scale · density (docs/sources.md).
  if (!m.emission.emits()) {
    if (!m.given.sigma) {
      m.sigma_s = glm::dvec3(c.smoke_albedo);
      m.sigma_a = glm::dvec3(1.0 - c.smoke_albedo);
    }
    if (!m.given.density_scale) m.density_scale = c.smoke_density_scale;
  }
}

}  // namespace pyrolume
