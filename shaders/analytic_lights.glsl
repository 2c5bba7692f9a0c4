// Analytic lights: the scene's `lights` (sun, point, spot, sphere), written
// from docs/lights.md "Analytic lights" independently of the CPU reference.
// Their values, the disc's radiance and the spot's cone are computed on the
// host (host/light/AnalyticLights) and packed into GpuLight.
//
// Contract with the includer: include shared/light_types.h and sampling.glsl
// and geometry.glsl, then declare
//   const uint LIGHT_COUNT (a specialisation constant; 0 compiles it all out)
//   layout(std430, binding = …) readonly buffer LightBlock { GpuLight analytic_lights[]; };
#ifndef PYROLUME_ANALYTIC_LIGHTS_GLSL
#define PYROLUME_ANALYTIC_LIGHTS_GLSL

// Point, spot and a distant light of angle 0: reached only by light sampling.
bool light_is_delta(uint kind) { return kind <= LIGHT_DISTANT; }

// A direction uniform in the cone around unit `axis` whose half-angle α has
// 1 − cos α = omc: 1 − cos = u·omc, sin from (1 − cos)(1 + cos) without the
// cancellation of 1 − cos in float (the sun's omc is ~1e-5).
vec3 sample_cone(vec3 axis, float omc, vec2 u) {
  const float a = u.x * omc;
  const float cos_a = 1.0 - a, sin_a = sqrt(max(a * (2.0 - a), 0.0));
  const float phi = 2.0 * PI * u.y;
  const vec3 t = any_perpendicular(axis), b = cross(axis, t);
  return normalize(cos_a * axis + sin_a * (cos(phi) * t + sin(phi) * b));
}

// 1 − cos θmax of the cone that sphere light l subtends from o: sin²θmax =
// r²/d², 1 − cos = sin² / (1 + cos). 0 from inside (no sample).
float sphere_light_omc(GpuLight l, vec3 o) {
  const vec3 v = l.position - o;
  const float d2 = dot(v, v), r2 = l.radius * l.radius;
  if (!(d2 > r2)) return 0.0;
  const float s2 = r2 / d2;
  return s2 / (1.0 + sqrt(1.0 - s2));
}

// Whether unit direction d lies in disc light l's cone: |d × axis|² ≤ sin²θ,
// which keeps its precision for small discs where cos does not.
bool in_disc(GpuLight l, vec3 d) {
  const vec3 c = cross(d, l.direction);
  return dot(d, l.direction) > 0.0 && dot(c, c) <= l.sin2;
}

// The solid-angle pdf with which light l, once picked, draws unit direction d
// from o: uniform over the disc's or the sphere's cone; 0 outside it and for
// delta lights.
float analytic_light_pdf(GpuLight l, vec3 o, vec3 d) {
  if (l.kind == LIGHT_DISC) return in_disc(l, d) ? 1.0 / (2.0 * PI * l.one_minus_cos) : 0.0;
  if (l.kind == LIGHT_SPHERE) {
    const vec3 v = l.position - o, c = cross(v, d);
    const float omc = sphere_light_omc(l, o);
    const bool hits = dot(v, d) > 0.0 && dot(c, c) <= l.radius * l.radius;
    return omc > 0.0 && hits ? 1.0 / (2.0 * PI * omc) : 0.0;
  }
  return 0.0;
}

// pbrt-v4's spot falloff: smoothstep from the cone's edge (cone.x) to where
// the falloff starts (cone.y); a hard edge when they are equal.
float spot_falloff(GpuLight l, float cos_a) {
  if (cos_a >= l.cos_falloff) return 1.0;
  if (cos_a < l.cos_cone) return 0.0;
  return smoothstep(l.cos_cone, l.cos_falloff, cos_a);
}

// A direction from o toward light l (false: none). Delta lights also give
// delta_value, what the light delivers along dir per unit of f: I·falloff/r²
// (point, spot) or E (distant); continuous lights leave it 0.
bool analytic_light_sample(GpuLight l, vec3 o, vec2 u, out vec3 dir, out vec3 delta_value) {
  dir = vec3(0.0, 0.0, 1.0);
  delta_value = vec3(0.0);
  const uint kind = l.kind;
  if (kind == LIGHT_POINT || kind == LIGHT_SPOT) {
    const vec3 v = l.position - o;
    const float d2 = dot(v, v);
    if (!(d2 > 0.0)) return false;
    dir = v * inversesqrt(d2);
    const float falloff = kind == LIGHT_SPOT ? spot_falloff(l, dot(-dir, l.direction)) : 1.0;
    delta_value = l.value * (falloff / d2);
    return falloff > 0.0;
  }
  if (kind == LIGHT_DISTANT) {
    dir = l.direction;
    delta_value = l.value;
    return true;
  }
  if (kind == LIGHT_DISC) {
    dir = sample_cone(l.direction, l.one_minus_cos, u);
    return true;
  }
  const float omc = sphere_light_omc(l, o);
  if (!(omc > 0.0)) return false;
  dir = sample_cone(normalize(l.position - o), omc, u);
  return true;
}

// The discs' radiance along an escaping direction d.
vec3 disc_lights_radiance(vec3 d) {
  vec3 L = vec3(0.0);
  for (uint i = 0u; i < LIGHT_COUNT; ++i)
    if (analytic_lights[i].kind == LIGHT_DISC && in_disc(analytic_lights[i], d)) L += analytic_lights[i].value;
  return L;
}

// The nearest sphere light that the ray o + t·d meets before t_max: its index
// (t_max then its distance), or LIGHT_COUNT. A ray that starts inside one
// meets it at once (t 0): the sphere is opaque.
uint intersect_sphere_lights(vec3 o, vec3 d, inout float t_max) {
  uint found = LIGHT_COUNT;
  for (uint i = 0u; i < LIGHT_COUNT; ++i) {
    if (analytic_lights[i].kind != LIGHT_SPHERE) continue;
    vec2 t;
    if (intersect_sphere(o, d, analytic_lights[i].position, analytic_lights[i].radius, t) && t.x < t_max) {
      t_max = t.x;
      found = i;
    }
  }
  return found;
}

// The radiance that a ray along d sees where it meets sphere light l at x:
// its radiance from outside, none from inside (it emits outward only).
vec3 sphere_light_radiance(GpuLight l, vec3 x, vec3 d) {
  return dot(d, x - l.position) < 0.0 ? l.value : vec3(0.0);
}
#endif
