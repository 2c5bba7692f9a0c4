// The pinhole camera (FrameConstants' camera_*; docs/scene-format.md "camera"),
// shared by the paths (render.comp) and the denoiser's guide (guide.comp).

// The camera ray's direction through film point pixel + jitter (jitter in [0,1)²).
vec3 camera_direction(uvec2 pixel, vec2 jitter) {
  vec2 ndc = vec2(2.0 * (float(pixel.x) + jitter.x) / float(frame.width) - 1.0,
                  1.0 - 2.0 * (float(pixel.y) + jitter.y) / float(frame.height));
  float tan_half = frame.tan_half_fov, aspect = frame.aspect;
  return normalize(frame.camera_forward + ndc.x * tan_half * aspect * frame.camera_right +
                   ndc.y * tan_half * frame.camera_up);
}
