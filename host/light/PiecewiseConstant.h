#pragma once
// 1D piecewise-constant distributions stored as float CDFs, the layout the GPU
// reads (shaders/lights.glsl does the same search with the same comparisons,
// so both pick the same bin for the same u).
#include <algorithm>
#include <cmath>
#include <cstddef>

namespace pyrolume {

// cdf[0..n]: cdf[0] = 0, cdf[n] = 1 exactly, cdf[i] ≈ Σ_{k<i} w_k / Σ w (summed in
// double, stored as float). A bin of weight > 0 always keeps a nonzero float
// width (nudged by one ulp where rounding would close it), so it can be sampled:
// coverage survives the float storage. Its probability is then exactly the
// width cdf[i+1] − cdf[i] of the stored values (bin_probability), which the
// samplers report as their pdf: sampling and pdf agree. A zero sum gives the
// uniform CDF (the caller must not sample it).
inline void build_cdf(const double* w, int n, float* cdf) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += w[i];
  cdf[0] = 0.0f;
  cdf[n] = 1.0f;
  if (!(sum > 0.0)) {
    for (int i = 1; i < n; ++i) cdf[i] = float(double(i) / n);
    return;
  }
  double acc = 0.0;
  for (int i = 1; i < n; ++i) {
    acc += w[i - 1];
    const float c = float(acc / sum);
    cdf[i] = w[i - 1] > 0.0 ? std::max(c, std::nextafter(cdf[i - 1], 2.0f)) : std::max(c, cdf[i - 1]);
  }
  for (int i = n - 1; i >= 1; --i)
    cdf[i] = w[i] > 0.0 ? std::min(cdf[i], std::nextafter(cdf[i + 1], -1.0f)) : std::min(cdf[i], cdf[i + 1]);
}

// The probability of bin i: the width of its stored CDF interval (exact in double).
inline double bin_probability(const float* cdf, int i) { return double(cdf[i + 1]) - double(cdf[i]); }

// The bin i ∈ [0, n) with cdf[i] <= u < cdf[i+1] (the largest i with
// cdf[i] <= u, so empty bins are never returned for u < 1), and the position of
// u inside it, in [0, 1): *offset = (u − cdf[i]) / (cdf[i+1] − cdf[i]).
inline int sample_cdf(const float* cdf, int n, double u, double* offset) {
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    const int mid = (lo + hi + 1) / 2;
    if (double(cdf[mid]) <= u)
      lo = mid;
    else
      hi = mid - 1;
  }
  const double a = cdf[lo], b = cdf[lo + 1];
  double t = b > a ? (u - a) / (b - a) : 0.0;
  *offset = std::clamp(t, 0.0, 0x1.fffffffffffffp-1);
  return lo;
}

}  // namespace pyrolume
