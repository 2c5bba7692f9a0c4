#include "image/Compare.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "image/ImageIo.h"
#include "util/Error.h"

namespace pyrolume {

namespace {

struct Sums {
  double sq = 0.0, rel = 0.0, a = 0.0, b = 0.0, var = 0.0;
  size_t n = 0;
  void add(const Sums& o) {
    sq += o.sq, rel += o.rel, a += o.a, b += o.b, var += o.var;
    n += o.n;
  }
  ChannelMetrics metrics(bool with_variance) const {
    ChannelMetrics m;
    if (n == 0) return m;
    m.rmse = std::sqrt(sq / double(n));
    m.rel_mse = rel / double(n);
    if (b != 0.0)
      m.bias = (a - b) / b;
    else
      m.bias = a == 0.0 ? 0.0 : std::copysign(std::numeric_limits<double>::infinity(), a);
    if (with_variance) m.bias_se = std::sqrt(var) / std::abs(b);
    return m;
  }
};

// Box-filtered variance over a (2r+1)² window clipped at the border, per channel.
std::vector<double> pooled_variance(const Image& img, int r) {
  std::vector<double> out(img.rgb.size(), 0.0);
  if (!img.has_variance()) return out;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      for (int c = 0; c < 3; ++c) {
        double s = 0.0;
        int count = 0;
        for (int yy = std::max(0, y - r); yy <= std::min(img.height - 1, y + r); ++yy)
          for (int xx = std::max(0, x - r); xx <= std::min(img.width - 1, x + r); ++xx) {
            s += img.var_at(xx, yy, c);
            ++count;
          }
        out[img.index(x, y, c)] = s / count;
      }
  return out;
}

std::string fmt(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

std::string line(const char* name, const ChannelMetrics& m, bool with_variance) {
  std::string s = std::string(name) + " rmse=" + fmt(m.rmse) + " rel_mse=" + fmt(m.rel_mse) + " bias=" + fmt(m.bias);
  if (with_variance) s += " bias_se=" + fmt(m.bias_se);
  return s + "\n";
}

}  // namespace

CompareReport compare_images(const Image& a, const Image& b, const CompareOptions& options, const std::string& a_name,
                             const std::string& b_name) {
  if (a.width != b.width || a.height != b.height)
    throw input_error(a_name, "",
                      "size " + std::to_string(a.width) + "x" + std::to_string(a.height) + " differs from reference " +
                          b_name + " (" + std::to_string(b.width) + "x" + std::to_string(b.height) + ")");
  if (options.variance_pool_radius < 0) throw std::invalid_argument("compare_images: negative variance_pool_radius");

  CompareReport rep;
  rep.width = a.width;
  rep.height = a.height;
  rep.a_has_variance = a.has_variance();
  rep.b_has_variance = b.has_variance();
  rep.has_variance = rep.a_has_variance || rep.b_has_variance;

  const int r = options.variance_pool_radius;
  std::vector<double> var_a, var_b;
  if (r > 0) {
    var_a = pooled_variance(a, r);
    var_b = pooled_variance(b, r);
  }
  auto variance = [&](const Image& img, const std::vector<double>& pooled, size_t i) -> double {
    if (!img.has_variance()) return 0.0;
    return r > 0 ? pooled[i] : double(img.variance[i]);
  };

  Sums ch[3];
  const size_t n = a.pixel_count() * 3;
  for (size_t i = 0; i < n; ++i) {
    const double va = a.rgb[i], vb = b.rgb[i], d = va - vb;
    Sums& s = ch[i % 3];
    s.sq += d * d;
    s.rel += d * d / (vb * vb + 1e-2);
    s.a += va;
    s.b += vb;
    s.n += 1;
    if (!std::isfinite(va) || !std::isfinite(vb)) ++rep.nonfinite;
    if (rep.has_variance) {
      // bias_se uses the raw variance: pooling is only for the per-pixel test.
      const double raw = (a.has_variance() ? double(a.variance[i]) : 0.0) + (b.has_variance() ? double(b.variance[i]) : 0.0);
      s.var += raw;
      const double var = variance(a, var_a, i) + variance(b, var_b, i);
      const double threshold = var > 0.0 ? 4.0 * std::sqrt(var) : 1e-6 * std::max(1.0, std::abs(vb));
      if (!(std::abs(d) <= threshold)) ++rep.outliers;  // NaN counts as an outlier
    }
  }
  Sums total;
  for (int c = 0; c < 3; ++c) {
    rep.channel[c] = ch[c].metrics(rep.has_variance);
    total.add(ch[c]);
  }
  rep.all = total.metrics(rep.has_variance);
  rep.bias_se = rep.all.bias_se;
  rep.outlier_fraction = n ? double(rep.outliers) / double(n) : 0.0;
  return rep;
}

std::string format_report(const CompareReport& rep) {
  std::string s = "size=" + std::to_string(rep.width) + "x" + std::to_string(rep.height) + "\n";
  const char* names[3] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c) s += line(names[c], rep.channel[c], rep.has_variance);
  s += line("all", rep.all, rep.has_variance);
  if (rep.has_variance) {
    const char* src = rep.a_has_variance && rep.b_has_variance ? "both" : rep.a_has_variance ? "a" : "b";
    s += "outliers_4sigma=" + fmt(rep.outlier_fraction) + " (" + std::to_string(rep.outliers) + " of " +
         std::to_string(size_t(rep.width) * size_t(rep.height) * 3) + ", variance: " + src + ")\n";
  }
  if (rep.nonfinite > 0) s += "nonfinite=" + std::to_string(rep.nonfinite) + "\n";
  return s;
}

int run_compare_command(const std::filesystem::path& a, const std::filesystem::path& b,
                        std::optional<double> max_relmse, std::optional<double> max_outliers, std::ostream& out,
                        std::ostream& err) {
  if (max_relmse && !(*max_relmse >= 0.0)) throw input_error("--max-relmse", "", "must be a number ≥ 0");
  if (max_outliers && !(*max_outliers >= 0.0)) throw input_error("--max-outliers", "", "must be a number ≥ 0");
  const Image ia = read_image(a), ib = read_image(b);
  if (max_outliers && !ia.has_variance() && !ib.has_variance())
    throw input_error(a.string(), "",
                      "--max-outliers needs variance channels (variance.R/G/B) in at least one image; "
                      "render with --variance");
  const CompareReport rep = compare_images(ia, ib, {}, a.string(), b.string());
  out << format_report(rep);

  int status = 0;
  // Negated comparisons so that NaN fails the gate.
  if (max_relmse && !(rep.all.rel_mse <= *max_relmse)) {
    err << "compare: rel_mse " << fmt(rep.all.rel_mse) << " exceeds --max-relmse " << fmt(*max_relmse) << "\n";
    status = 3;
  }
  if (max_outliers && !(rep.outlier_fraction <= *max_outliers)) {
    err << "compare: outliers_4sigma " << fmt(rep.outlier_fraction) << " exceeds --max-outliers "
        << fmt(*max_outliers) << "\n";
    status = 3;
  }
  return status;
}

}  // namespace pyrolume
