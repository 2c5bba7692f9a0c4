#pragma once
// Counter-based random numbers for the CPU reference: every camera sample owns a
// PCG32 stream keyed by (seed, frame, pixel, sample), so images do not depend on
// the thread count or on scheduling (bit-identical reruns).
#include <cstdint>

namespace pyrolume::cpu {

// SplitMix64 finaliser (Steele et al. 2014): a bijective 64-bit mix, used to turn
// structured keys (small consecutive integers) into well-spread PCG seeds.
inline uint64_t mix64(uint64_t z) {
  z += 0x9e3779b97f4a7c15ull;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

// PCG32 (O'Neill 2014, pcg32_random_r / pcg32_srandom_r): 64-bit LCG state,
// XSH-RR output.
class Pcg32 {
 public:
  Pcg32(uint64_t initstate, uint64_t initseq) {
    state_ = 0;
    inc_ = (initseq << 1u) | 1u;
    next_u32();
    state_ += initstate;
    next_u32();
  }

  // One stream per camera sample: the key is hashed twice (state and stream
  // selector) so neighbouring pixels and samples get unrelated sequences.
  static Pcg32 for_sample(uint32_t seed, uint32_t frame, uint64_t pixel, uint64_t sample) {
    uint64_t k = mix64((uint64_t(seed) << 32) | frame);
    k = mix64(k ^ pixel);
    k = mix64(k ^ (sample * 0xd1b54a32d192ed03ull));
    return Pcg32(k, mix64(k ^ 0x5851f42d4c957f2dull));
  }

  uint32_t next_u32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    uint32_t xorshifted = uint32_t(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = uint32_t(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }

  // Uniform double in [0, 1) with 53 random bits (never 1.0).
  double uniform() {
    uint64_t hi = next_u32(), lo = next_u32();
    return double(((hi << 32) | lo) >> 11) * 0x1.0p-53;
  }

 private:
  uint64_t state_ = 0, inc_ = 1;
};

}  // namespace pyrolume::cpu
