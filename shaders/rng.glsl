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
#endif
