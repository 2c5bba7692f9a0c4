// Ray intersections with medium bounds: entry/exit distances along the ray,
// clipped to t >= 0 (a ray starting inside gets t_enter = 0).
#ifndef PYROLUME_GEOMETRY_GLSL
#define PYROLUME_GEOMETRY_GLSL

// Returns false when the ray misses or the interval lies behind the origin.
bool intersect_sphere(vec3 o, vec3 d, vec3 center, float radius, out vec2 t) {
  // Stable quadratic (pbrt-v4 / Ray Tracing Gems ch. 7): b' = dot(oc, d),
  // discriminant from |oc - b' d|² to avoid cancellation for far spheres.
  vec3 oc = o - center;
  float b = dot(oc, d);
  vec3 perp = oc - b * d;
  float disc = radius * radius - dot(perp, perp);
  if (disc <= 0.0) return false;
  float q = -b - sign(b) * sqrt(disc);
  if (b == 0.0) q = -sqrt(disc);
  float t0 = q;
  float t1 = (dot(oc, oc) - radius * radius) / q;
  if (q == 0.0) t1 = -t0;
  t = vec2(max(min(t0, t1), 0.0), max(t0, t1));
  return t.y > t.x;
}

bool intersect_box(vec3 o, vec3 d, vec3 bmin, vec3 bmax, out vec2 t) {
  vec3 inv = 1.0 / d;  // ±inf on axis-parallel rays is what the slab test wants
  vec3 ta = (bmin - o) * inv, tb = (bmax - o) * inv;
  vec3 tmin = min(ta, tb), tmax = max(ta, tb);
  // A ray inside a slab and parallel to it gives (-inf, inf); NaN from 0*inf is
  // excluded by max/min picking the other operand.
  float t0 = max(max(tmin.x, tmin.y), max(tmin.z, 0.0));
  float t1 = min(min(tmax.x, tmax.y), tmax.z);
  t = vec2(t0, t1);
  return t1 > t0;
}
#endif
