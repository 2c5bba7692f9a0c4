// gen_sky: writes a procedural sky as a lat-long (equirectangular) EXR in the
// convention of host/light/EnvironmentMap (Blender's: +Z up, row 0 = zenith,
// the centre column looks along +X, u grows clockwise seen from above).
//
//   gen_sky OUT.exr [--width W] [--height H] [--sun-elevation DEG]
//           [--sun-azimuth DEG] [--sun-radiance L] [--float]
//
// A clear sky: a blue gradient from a pale horizon (≈ 0.6) to a deeper zenith
// (≈ 0.3 in green), a warm glow around the sun, a soft sun disc of 1.5° radius
// (radiance L, default 60: with its ~2e-3 sr it adds about a tenth of the
// sky's own irradiance, so it casts shadows without firefly-level peaks), and a
// dark ground (≈ 0.05) below the horizon, blended over 2°. Linear radiance in
// arbitrary units ~1; scale it with the scene's `environment.scale`.
// --sun-azimuth is φ in the map frame, counter-clockwise from +X seen from
// above (+Y is 90°). Each texel averages 4×4 directions, so the disc is
// anti-aliased. Stored as half floats with ZIP compression (--float: 32-bit).
// Deterministic: no random numbers.
#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <half.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Rgb {
  double r = 0, g = 0, b = 0;
};
Rgb operator+(Rgb a, Rgb b) { return {a.r + b.r, a.g + b.g, a.b + b.b}; }
Rgb operator*(double s, Rgb a) { return {s * a.r, s * a.g, s * a.b}; }

double smoothstep(double a, double b, double x) {
  const double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

struct Sky {
  double sun_elevation = 25.0 * kPi / 180.0, sun_azimuth = 140.0 * kPi / 180.0, sun_radiance = 60.0;

  Rgb radiance(double x, double y, double z) const {
    const double elev = std::asin(std::clamp(z, -1.0, 1.0));
    const double sx = std::cos(sun_elevation) * std::cos(sun_azimuth);
    const double sy = std::cos(sun_elevation) * std::sin(sun_azimuth);
    const double sz = std::sin(sun_elevation);
    const double gamma = std::acos(std::clamp(x * sx + y * sy + z * sz, -1.0, 1.0));  // angle to the sun
    // Sky: pale at the horizon, deeper blue towards the zenith.
    const Rgb horizon{0.60, 0.68, 0.80}, zenith{0.10, 0.26, 0.62};
    const double t = 1.0 - std::exp(-3.0 * std::max(elev, 0.0));
    Rgb sky = (1.0 - t) * horizon + t * zenith;
    // Glow around the sun (forward scattering), stronger near the horizon.
    sky = sky + (0.9 * std::exp(-gamma / 0.15) + 0.25 * std::exp(-gamma / 0.6)) * Rgb{1.0, 0.78, 0.52};
    // Sun disc, 1.5° radius with a soft 0.3° edge.
    const double disc = 1.0 - smoothstep(1.2 * kPi / 180.0, 1.8 * kPi / 180.0, gamma);
    sky = sky + disc * sun_radiance * Rgb{1.0, 0.93, 0.82};
    // Ground below the horizon (a dark, slightly warm brown), blended over 2°.
    const Rgb ground{0.055, 0.050, 0.045};
    const double g = smoothstep(0.0, 2.0 * kPi / 180.0, -elev);
    return (1.0 - g) * sky + g * ground;
  }
};

// To stderr with status 2 for a bad command line; to stdout with 0 for --help.
int usage(bool asked = false) {
  std::fprintf(asked ? stdout : stderr,
               "usage: gen_sky OUT.exr [--width W] [--height H] [--sun-elevation DEG] [--sun-azimuth DEG] "
               "[--sun-radiance L] [--float]\n");
  return asked ? 0 : 2;
}

}  // namespace

int main(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--help" || std::string(argv[i]) == "-h") return usage(true);
  if (argc < 2 || argv[1][0] == '-') {  // the first argument is the output, never an option
    std::fprintf(stderr, "gen_sky: %s\n", argc < 2 ? "no output file given" : ("expected OUT.exr first, not " + std::string(argv[1])).c_str());
    return usage();
  }
  std::string out = argv[1];
  int W = 512, H = 256;
  bool as_float = false;
  Sky sky;
  for (int i = 2; i < argc; ++i) {
    std::string a = argv[i];
    auto next = [&]() -> double {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "gen_sky: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      char* end = nullptr;
      const double v = std::strtod(argv[++i], &end);
      if (!end || *end || !std::isfinite(v)) {
        std::fprintf(stderr, "gen_sky: %s: not a number: %s\n", a.c_str(), argv[i]);
        std::exit(2);
      }
      return v;
    };
    if (a == "--width") W = int(next());
    else if (a == "--height") H = int(next());
    else if (a == "--sun-elevation") sky.sun_elevation = next() * kPi / 180.0;
    else if (a == "--sun-azimuth") sky.sun_azimuth = next() * kPi / 180.0;
    else if (a == "--sun-radiance") sky.sun_radiance = next();
    else if (a == "--float") as_float = true;
    else {
      std::fprintf(stderr, "gen_sky: unknown argument %s\n", a.c_str());
      return usage();
    }
  }
  if (W < 4 || H < 2 || W > 16384 || H > 8192 || sky.sun_radiance < 0) {
    std::fprintf(stderr, "gen_sky: --width %d --height %d --sun-radiance %g: the size must be 4..16384 x 2..8192 and the radiance >= 0\n", W, H, sky.sun_radiance);
    return 2;
  }

  // Texel (i, j): u ∈ [i/W, (i+1)/W), v ∈ [j/H, (j+1)/H); θ = πv, φ = π − 2πu.
  std::vector<float> rgb(size_t(W) * H * 3);
  constexpr int S = 4;
  for (int j = 0; j < H; ++j)
    for (int i = 0; i < W; ++i) {
      Rgb acc;
      double wsum = 0.0;
      for (int sy = 0; sy < S; ++sy)
        for (int sx = 0; sx < S; ++sx) {
          const double u = (i + (sx + 0.5) / S) / W, v = (j + (sy + 0.5) / S) / H;
          const double theta = kPi * v, phi = kPi - 2 * kPi * u;
          const double w = std::sin(theta);  // solid-angle weight inside the texel
          acc = acc + w * sky.radiance(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                                       std::cos(theta));
          wsum += w;
        }
      float* p = &rgb[(size_t(j) * W + i) * 3];
      p[0] = float(acc.r / wsum);
      p[1] = float(acc.g / wsum);
      p[2] = float(acc.b / wsum);
    }

  const std::filesystem::path dest(out);
  const std::filesystem::path tmp = dest.parent_path() / ("." + dest.filename().string() + ".tmp");
  try {
    Imf::Header header(W, H);
    header.compression() = Imf::ZIP_COMPRESSION;
    const Imf::PixelType type = as_float ? Imf::FLOAT : Imf::HALF;
    const char* names[3] = {"R", "G", "B"};
    for (const char* n : names) header.channels().insert(n, Imf::Channel(type));
    std::vector<half> halves;
    Imf::FrameBuffer fb;
    if (as_float) {
      for (int c = 0; c < 3; ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(rgb.data() + c), 3 * sizeof(float), size_t(W) * 3 * sizeof(float)));
    } else {
      halves.assign(rgb.begin(), rgb.end());
      for (int c = 0; c < 3; ++c)
        fb.insert(names[c], Imf::Slice(Imf::HALF, (char*)(halves.data() + c), 3 * sizeof(half), size_t(W) * 3 * sizeof(half)));
    }
    {
      Imf::OutputFile file(tmp.string().c_str(), header);
      file.setFrameBuffer(fb);
      file.writePixels(H);
    }
    std::filesystem::rename(tmp, dest);
  } catch (const std::exception& e) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    std::fprintf(stderr, "%s: %s\n", out.c_str(), e.what());
    return 2;
  }
  std::printf("%s: %d x %d, %s\n", out.c_str(), W, H, as_float ? "float" : "half");
  return 0;
}
