// `pyrolume blackbody`: the blackbody locus and colours as CSV, plus a swatch strip.
#include <cmath>
#include <cstdio>
#include <exception>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "color/Blackbody.h"
#include "color/SwatchStrip.h"

namespace pyrolume::color {
namespace {

std::string num(double v, const char* fmt) {
  if (std::isnan(v)) return "nan";  // printf may print "-nan"
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v);
  return buf;
}

}  // namespace

int run_blackbody_command(double from_k, double to_k, double step_k, BlackbodyMode mode, int observer,
                          const std::string& png_path, std::ostream& out, std::ostream& err,
                          const OutputWriter& write_output) {
  auto bad = [&](const std::string& key, const std::string& reason) {
    err << "blackbody: " << key << ": " << reason << "\n";
    return 2;
  };
  const std::pair<const char*, double> args[] = {{"--from", from_k}, {"--to", to_k}, {"--step", step_k}};
  for (auto [key, v] : args)
    if (!std::isfinite(v)) return bad(key, "must be a finite number, got " + num(v, "%g"));
  if (from_k < 0.0) return bad("--from", "temperatures are kelvin >= 0, got " + num(from_k, "%g"));
  if (to_k < from_k) return bad("--to", "must be >= --from (" + num(to_k, "%g") + " < " + num(from_k, "%g") + ")");
  if (!(step_k > 0.0)) return bad("--step", "must be > 0, got " + num(step_k, "%g"));
  if (observer != 2 && observer != 10) return bad("--observer", "must be 2 or 10, got " + std::to_string(observer));
  const double rows = std::floor((to_k - from_k) / step_k * (1.0 + 1e-12) + 1e-9) + 1.0;
  if (!(rows <= double(kMaxBlackbodyRows)))
    return bad("--step", num(rows, "%.0f") + " rows requested, at most " + std::to_string(kMaxBlackbodyRows));

  // --to is inclusive; the tolerance absorbs from + i·step rounding just above to.
  // At most `rows`: where step is below the spacing of doubles (1e300 + 1 ==
  // 1e300) t would never pass --to.
  std::vector<double> temperatures;
  for (long i = 0; i < long(rows); ++i) {
    const double t = from_k + double(i) * step_k;
    if (!(t <= to_k + 1e-9 * step_k)) break;
    temperatures.push_back(t);
  }

  // The PNG first: if it fails, no CSV is printed (one line on stderr, status 2).
  if (!png_path.empty()) {
    if (temperatures.size() > size_t(kMaxSwatches))
      return bad("--png", std::to_string(temperatures.size()) + " temperatures, the strip takes at most " +
                              std::to_string(kMaxSwatches));
    try {
      const SwatchStrip strip = render_swatch_strip(temperatures, observer);
      write_output(png_path, [&](std::ostream& os) { encode_swatch_strip_png(os, strip); });
    } catch (const std::exception& e) {
      return bad("--png", e.what());
    }
  }
  std::ostringstream csv;
  csv << "kelvin,x,y,r,g,b\n";
  for (double t : temperatures) {
    const glm::dvec2 xy = blackbody_xy(t, observer);
    const glm::dvec3 rgb = blackbody_rgb(t, mode, observer);
    csv << num(t, "%.10g") << ',' << num(xy.x, "%.6f") << ',' << num(xy.y, "%.6f") << ',' << num(rgb.r, "%.6g") << ','
        << num(rgb.g, "%.6g") << ',' << num(rgb.b, "%.6g") << '\n';
  }
  out << csv.str();
  out.flush();
  return 0;
}

}  // namespace pyrolume::color
