// Sampling routines. The CPU reference uses the same names and argument order
// (sample_hg, hg_pdf, sample_free_flight) so the two can be read side by side.
#ifndef PYROLUME_SAMPLING_GLSL
#define PYROLUME_SAMPLING_GLSL

const float PI = 3.14159265358979;

// Exponential free flight with rate sigma: t = -ln(1 - u) / sigma (pdf sigma·exp(-sigma·t)).
float sample_free_flight(float sigma, float u) {
  return -log(1.0 - u) / sigma;
}

// Henyey–Greenstein phase function; cos_theta is between the travel direction
// before and after scattering, so g > 0 scatters forward:
// p = (1 - g²) / (4π (1 + g² - 2g cosθ)^{3/2}).
float hg_pdf(float cos_theta, float g) {
  float denom = 1.0 + g * g - 2.0 * g * cos_theta;
  return (1.0 - g * g) / (4.0 * PI * denom * sqrt(max(denom, 1e-12)));
}

vec3 any_perpendicular(vec3 d) {
  return abs(d.x) > 0.9 ? normalize(cross(d, vec3(0, 1, 0))) : normalize(cross(d, vec3(1, 0, 0)));
}

// Invert the HG CDF (pbrt-v4 SampleHenyeyGreenstein, with its wo = -dir):
// cosθ = (1 + g² - ((1 - g²) / (1 - g + 2gξ))²) / (2g); isotropic below |g| = 1e-3.
vec3 sample_hg(vec3 dir, float g, vec2 u) {
  float cos_theta;
  if (abs(g) < 1e-3) {
    cos_theta = 1.0 - 2.0 * u.x;
  } else {
    float s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u.x);
    cos_theta = clamp((1.0 + g * g - s * s) / (2.0 * g), -1.0, 1.0);
  }
  float sin_theta = sqrt(max(0.0, 1.0 - cos_theta * cos_theta));
  float phi = 2.0 * PI * u.y;
  vec3 t = any_perpendicular(dir);
  vec3 b = cross(dir, t);
  return normalize(cos_theta * dir + sin_theta * (cos(phi) * t + sin(phi) * b));
}
// Cosine-weighted direction on the hemisphere around unit n (Malley's method):
// pdf = cos θ / π.
vec3 sample_cosine_hemisphere(vec3 n, vec2 u) {
  float r = sqrt(u.x), phi = 2.0 * PI * u.y;
  vec3 t = any_perpendicular(n);
  vec3 b = cross(n, t);
  return normalize(r * cos(phi) * t + r * sin(phi) * b + sqrt(max(0.0, 1.0 - u.x)) * n);
}
#endif
