#include "render/cpu/Transmittance.h"

#include <vector>

#include "render/cpu/Sampling.h"

namespace pyrolume::cpu {

namespace {

// Walks the tentative collisions of [0, t_max] segment by segment (the majorant
// is constant between consecutive cuts); `at_collision(sigma_t, sigma_maj)`
// returns false to stop. Returns false when stopped early.
template <class F>
bool for_each_tentative_collision(const MediaData& md, int c, const glm::dvec3& o, const glm::dvec3& d,
                                  double t_max, Pcg32& rng, TrackingCounters* counters, F at_collision) {
  thread_local std::vector<Span> spans;
  thread_local std::vector<double> cuts;
  thread_local std::vector<int> present;
  ray_spans(md, o, d, spans, cuts);
  uint64_t* lookups = counters ? &counters->density_lookups : nullptr;
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double a = cuts[k];
    if (!(a < t_max)) break;
    const double b = std::min(cuts[k + 1], t_max);
    const double sigma_maj = media_present(md, spans, a, cuts[k + 1], c, present);
    if (!(sigma_maj > 0.0)) continue;
    for (double t = a;;) {
      t += sample_free_flight(sigma_maj, rng.uniform());
      if (!(t < b)) break;  // memoryless: the next segment starts afresh
      const double sigma_t = sigma_t_at(md, present, c, o + t * d, lookups);
      if (counters && exceeds_majorant(sigma_t, sigma_maj)) ++counters->majorant_violations;
      if (!at_collision(sigma_t, sigma_maj)) return false;
    }
  }
  return true;
}

}  // namespace

double ratio_tracking_transmittance(const MediaData& md, int c, const glm::dvec3& o, const glm::dvec3& d,
                                    double t_max, Pcg32& rng, TrackingCounters* counters) {
  double T = 1.0;
  for_each_tentative_collision(md, c, o, d, t_max, rng, counters, [&](double sigma_t, double sigma_maj) {
    // With a bounding majorant the factor is in [0, 1]. A violation (counted)
    // makes it negative; roulette then ends the path at 0, so results are only
    // to be trusted with majorant_violations == 0.
    T *= 1.0 - sigma_t / sigma_maj;
    if (T < kRatioTrackingRouletteBelow) {
      if (!(rng.uniform() < T)) {
        T = 0.0;
        return false;
      }
      T = 1.0;  // survived with probability T: weight T / T
    }
    return true;
  });
  return T;
}

double delta_tracking_transmittance(const MediaData& md, int c, const glm::dvec3& o, const glm::dvec3& d,
                                    double t_max, Pcg32& rng, TrackingCounters* counters) {
  bool escaped = for_each_tentative_collision(md, c, o, d, t_max, rng, counters, [&](double sigma_t, double sigma_maj) {
    return !(rng.uniform() * sigma_maj < sigma_t);  // real collision: stop
  });
  return escaped ? 1.0 : 0.0;
}

}  // namespace pyrolume::cpu
