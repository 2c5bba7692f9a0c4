#include "geometry/Surfaces.h"

namespace pyrolume::geometry {

bool intersect(const Surfaces& s, const Ray& ray, double t_max, SurfaceHit& hit) {
  bool found = intersect(s.bvh, ray, t_max, hit);
  double t_closest = found ? hit.t : t_max;
  for (uint32_t i = 0; i < s.shapes.size(); ++i) {
    SurfaceHit h;
    if (intersect_shape(s.shapes[i], ray, t_closest, h)) {
      h.primitive = i;
      hit = h;
      t_closest = h.t;
      found = true;
    }
  }
  return found;
}

bool occluded(const Surfaces& s, const Ray& ray, double t_max) {
  for (const SurfaceShape& shape : s.shapes) {
    SurfaceHit h;
    if (intersect_shape(shape, ray, t_max, h)) return true;
  }
  return occluded(s.bvh, ray, t_max);
}

glm::dvec3 albedo_at(const Surfaces& s, const SurfaceHit& hit) {
  if (hit.material >= s.materials.size()) return glm::dvec3(0.5);
  const Material& m = s.materials[hit.material];
  if (m.texture < 0 || size_t(m.texture) >= s.textures.size()) return m.albedo;
  return m.albedo * s.textures[size_t(m.texture)].lookup(hit.uv);
}

}  // namespace pyrolume::geometry
