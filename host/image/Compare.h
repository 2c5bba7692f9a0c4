#pragma once
// Error metrics between a test image A and a reference B (`pyrolume compare`, the
// benchmark's error numbers, shader-vs-CPU tests). Sums run in double.
//
// Over the N pixels of one channel (or the 3N pixel-channels for "all"):
//   RMSE    = sqrt( mean (a − b)² )
//   relMSE  = mean( (a − b)² / (b² + 1e-2) )   — pbrt/Mitsuba relative MSE; the
//             1e-2 keeps black reference pixels from dominating.
//   bias    = (Σa − Σb) / Σb                   — docs/testing.md; 0 when both
//             sums are 0, ±inf when only Σb is.
//   bias_se = sqrt(Σvar_a + Σvar_b) / |Σb|     — standard error of bias, from the
//             per-pixel variance of the mean; only when variance is known.
// 4σ outliers: a pixel-channel is an outlier when |a − b| > 4·sqrt(var_a + var_b);
//   where var_a + var_b = 0 it is one when |a − b| > 1e-6·max(1, |b|). NaN/Inf
//   pixel-channels always count as outliers and make the metrics NaN/Inf (a CI
//   gate must not pass them).
// Variance: an image without variance channels counts as exact (var 0), so a
// render with variance can be tested against an analytic reference. has_variance
// is true when at least one image carries variance.
#include <cstddef>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>

#include "image/Image.h"

namespace pyrolume {

struct ChannelMetrics {
  double rmse = 0.0, rel_mse = 0.0, bias = 0.0;
  double bias_se = 0.0;  // 0 when neither image has variance
};

struct CompareOptions {
  // Per-pixel variance from n samples has n−1 degrees of freedom; averaging it over
  // a (2r+1)² neighbourhood (clipped at the border) steadies the 4σ test
  // (docs/testing.md: pool over 3×3, i.e. radius 1). 0 = no pooling.
  int variance_pool_radius = 0;
};

struct CompareReport {
  int width = 0, height = 0;
  ChannelMetrics channel[3];  // R, G, B
  ChannelMetrics all;         // over all pixel-channels
  bool has_variance = false;  // at least one image carries variance
  bool a_has_variance = false, b_has_variance = false;
  double outlier_fraction = 0.0;  // pixel-channels beyond 4σ ÷ 3N; 0 without variance
  size_t outliers = 0;            // pixel-channels beyond 4σ
  double bias_se = 0.0;           // == all.bias_se
  size_t nonfinite = 0;           // pixel-channels where a or b is NaN/Inf
};

// b is the reference. Different sizes → InputError naming both (a_name, b_name).
CompareReport compare_images(const Image& a, const Image& b, const CompareOptions& options = {},
                             const std::string& a_name = "A", const std::string& b_name = "B");

// One metric group per line, key=value, %.6g; stable for scripts:
//   size=WxH
//   R rmse=… rel_mse=… bias=…[ bias_se=…]      (also G, B)
//   all rmse=… rel_mse=… bias=…[ bias_se=…]
//   outliers_4sigma=… (N of M, variance: a|b|both)   — only with variance
//   nonfinite=N                                      — only when N > 0
std::string format_report(const CompareReport& report);

// `pyrolume compare A B [--max-relmse X] [--max-outliers F]`: reads both images,
// prints format_report to out, returns 0 when within limits and 3 when beyond
// (README.md "Using it": exit status; a limit check uses all.rel_mse and outlier_fraction, and
// NaN counts as beyond), with one line per exceeded limit on err. Unreadable
// files, size mismatch, a negative limit, or --max-outliers without variance in
// either image → InputError (the CLI maps it to exit 2).
int run_compare_command(const std::filesystem::path& a, const std::filesystem::path& b,
                        std::optional<double> max_relmse, std::optional<double> max_outliers, std::ostream& out,
                        std::ostream& err);

}  // namespace pyrolume
