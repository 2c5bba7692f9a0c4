#pragma once
// Unbiased transmittance estimators of the CPU reference for shadow rays:
// T(o → o + t_max·d) = exp(−∫₀^t_max σt_c(o + t·d) dt) in one colour channel c,
// through all of the scene's media (homogeneous and grid, overlapping ones add),
// with the same majorants as the reference's delta-tracking walk (Media.h).
#include <cstdint>

#include <glm/glm.hpp>

#include "render/cpu/Media.h"
#include "render/cpu/Rng.h"

namespace pyrolume::cpu {

struct TrackingCounters {
  uint64_t density_lookups = 0;      // trilinear density-texture samples
  uint64_t majorant_violations = 0;  // tentative collisions with σt > σ̄ (must stay 0)
};

// Below this running estimate, ratio tracking plays Russian roulette.
inline constexpr double kRatioTrackingRouletteBelow = 0.1;

// Ratio tracking (Novák et al. 2014, "Residual ratio tracking for estimating
// attenuation in participating media", eq. 6): sample tentative collisions with
// the majorant σ̄ as in delta tracking and multiply the estimate by the null
// probability 1 − σt(x)/σ̄ at each, instead of ending at a real one. Once the
// estimate T drops below kRatioTrackingRouletteBelow the path survives with
// probability T and then carries weight T / T = 1, else returns 0: unbiased
// (E = T·1 + (1 − T)·0 = T) and it ends long, dark shadow rays early.
// d must be unit length; t_max may be infinite. Returns a value in [0, 1].
double ratio_tracking_transmittance(const MediaData& md, int c, const glm::dvec3& o, const glm::dvec3& d,
                                    double t_max, Pcg32& rng, TrackingCounters* counters = nullptr);

// Delta tracking (Woodcock et al. 1965): sample tentative collisions with σ̄,
// accept one as real with probability σt(x)/σ̄ and return 0, or return 1 when
// the flight passes t_max. E = T; a 0/1 estimate.
double delta_tracking_transmittance(const MediaData& md, int c, const glm::dvec3& o, const glm::dvec3& d,
                                    double t_max, Pcg32& rng, TrackingCounters* counters = nullptr);

}  // namespace pyrolume::cpu
