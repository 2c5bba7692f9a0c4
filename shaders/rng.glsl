// Counter-based random numbers: every sample's stream is keyed on
// (seed, frame, pixel, sample index), so any pixel or frame re-renders
// bit-identically whatever the dispatch order (needed for animation and farms).
#ifndef PYROLUME_RNG_GLSL
#define PYROLUME_RNG_GLSL

// PCG-RXS-M-XS 32-bit hash (Jarzynski & Olano 2020, "Hash Functions for GPU Rendering").
uint pcg_hash(uint v) {
  uint state = v * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  return (word >> 22u) ^ word;
}

uint rng_init(uint seed, uint frame, uint pixel, uint sample_index) {
  return pcg_hash(sample_index ^ pcg_hash(pixel ^ pcg_hash(frame ^ pcg_hash(seed))));
}

// Uniform in [0, 1): advance an LCG, then hash the state (PCG output permutation).
float rng_next(inout uint state) {
  state = state * 747796405u + 2891336453u;
  uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
  word = (word >> 22u) ^ word;
  return float(word >> 8u) * (1.0 / 16777216.0);
}
// Sample k's point in its pixel: the k-th point of the R2 sequence (Roberts
// 2018: k·(1/g, 1/g²) mod 1, g the plastic number, in 32-bit fixed point so
// it stays exact for any k), shifted by one random offset per pixel
// (Cranley–Patterson rotation). Each point alone is uniform in the pixel (the
// offset is), so the pixel mean stays unbiased; together a pixel's first N
// points cover it far more evenly than N independent ones, and the pixel's
// spatial variation stops adding noise. Keyed on (seed, frame, pixel) only,
// so every sample is still reproducible on its own.
vec2 film_jitter(uint seed, uint frame, uint pixel, uint k) {
  const uint rx = pcg_hash(pcg_hash(pixel ^ pcg_hash(frame ^ pcg_hash(seed))) ^ 0x2545f491u);
  const uint ry = pcg_hash(rx);
  const uvec2 u = uvec2(k * 3242174889u + rx, k * 2447445414u + ry);
  return vec2(u >> 8u) * (1.0 / 16777216.0);
}
#endif
