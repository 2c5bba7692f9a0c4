// What a ray that leaves the scene sees, shared by the paths (render.comp)
// and the denoiser's guide (guide.comp).

// Radiance of a ray that leaves the scene: the environment map (+Z up,
// docs/lights.md) or the constant background, and the sun discs of the
// scene's distant lights.
vec3 escaped_radiance(vec3 d) {
  const vec3 sky = HAS_ENVIRONMENT ? env_radiance(environment, d) : frame.background;
  return LIGHT_COUNT > 0u ? sky + disc_lights_radiance(d) : sky;
}
