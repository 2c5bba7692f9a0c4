// The environment light (host/light/EnvironmentMap): the +Z-up lat-long
// convention and rotation, the pdf's normalisation, and sampling against the
// pdf by a chi-square test on direction bins (tests/support/Stats.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>

#include "color/ColorSpace.h"
#include "image/ImageIo.h"
#include "light/EnvironmentMap.h"
#include "render/vulkan/LightPacking.h"
#include "support/LightScenes.h"
#include "support/Stats.h"
#include "support/TestSupport.h"
#include "util/Error.h"
#include "util/Math.h"

using namespace pyrolume;

namespace {


// A map with structure everywhere the sampler must get right: a sky gradient,
// a bright small "sun", a black band (zero rows' neighbours) and black columns.
Image test_map(int W, int H) {
  return pyrolume::test::sky_image(
      W, H, [](double u, double v) { return glm::dvec3(0.2 + 0.8 * (1.0 - v), 0.3 + 0.5 * u, 1.0 - 0.5 * v); },
      [&](int i, int j) {
        return (j >= H * 5 / 8 && j < H * 6 / 8)     // black band
               || i == W / 3 || i == W / 3 + 1;  // black columns
      },
      {{0.7, 0.3}, 0.004, {40.0, 30.0, 20.0}});  // the sun
}

glm::dvec3 dir_from(double cos_theta, double phi) {
  const double s = std::sqrt(std::max(0.0, 1.0 - cos_theta * cos_theta));
  return {s * std::cos(phi), s * std::sin(phi), cos_theta};
}

// Direction bins in the WORLD frame, (cos θ, φ) cells of equal solid angle, so
// they cut across the map's texels whatever the rotation.
struct DirBins {
  int n_cos = 12, n_phi = 24;
  int count() const { return n_cos * n_phi; }
  int bin(const glm::dvec3& d) const {
    const double ct = std::clamp(d.z / glm::length(d), -1.0, 1.0);
    double phi = std::atan2(d.y, d.x);
    if (phi < 0) phi += 2 * kPi;
    const int a = std::min(int((ct + 1.0) / 2.0 * n_cos), n_cos - 1);
    const int b = std::min(int(phi / (2 * kPi) * n_phi), n_phi - 1);
    return a * n_phi + b;
  }
  // ∫ pdf dω over each bin, numerically: dω = sinθ dθ dφ, and each bin is cut
  // at the map's texel edges (rows: θ = πj/H; columns: φ = π − 2πi/W + rotation)
  // so that pdf·sinθ is constant on every piece (a piecewise-constant p_uv
  // over 2π²) and sub×sub midpoints integrate it without discretisation error
  // when pdf() is right.
  std::vector<double> integrate(const std::function<double(const glm::dvec3&)>& pdf, const EnvironmentMap& env,
                                int sub = 2) const {
    std::vector<double> out(count(), 0.0);
    const int W = env.width(), H = env.height();
    const double rot = env.rotation_deg() * kPi / 180.0;
    for (int a = 0; a < n_cos; ++a) {
      const double th0 = std::acos(std::min(1.0, -1.0 + 2.0 * (a + 1) / n_cos));  // smaller θ
      const double th1 = std::acos(std::max(-1.0, -1.0 + 2.0 * a / n_cos));
      std::vector<double> tb = {th0, th1};
      for (int j = 1; j < H; ++j)
        if (kPi * j / H > th0 && kPi * j / H < th1) tb.push_back(kPi * j / H);
      std::sort(tb.begin(), tb.end());
      for (int b = 0; b < n_phi; ++b) {
        const double p0 = 2 * kPi * b / n_phi, p1 = 2 * kPi * (b + 1) / n_phi;
        std::vector<double> pb = {p0, p1};
        for (int i = 0; i < W; ++i) {
          double phi = kPi - 2 * kPi * i / W + rot;
          phi -= 2 * kPi * std::floor(phi / (2 * kPi));
          if (phi > p0 && phi < p1) pb.push_back(phi);
        }
        std::sort(pb.begin(), pb.end());
        double acc = 0.0;
        for (size_t x = 0; x + 1 < tb.size(); ++x)
          for (size_t y = 0; y + 1 < pb.size(); ++y) {
            const double dth = (tb[x + 1] - tb[x]) / sub, dph = (pb[y + 1] - pb[y]) / sub;
            for (int sx = 0; sx < sub; ++sx)
              for (int sy = 0; sy < sub; ++sy) {
                const double th = tb[x] + (sx + 0.5) * dth;
                acc += pdf(dir_from(std::cos(th), pb[y] + (sy + 0.5) * dph)) * std::sin(th) * dth * dph;
              }
          }
        out[a * n_phi + b] = acc;
      }
    }
    return out;
  }

  // The exact probability of each bin under env's sampling density: the bins
  // are rectangles in (u, v) too (rotation about Z shifts φ only), and
  // pdf dω = p_uv du dv with p_uv piecewise constant over texels.
  std::vector<double> exact(const EnvironmentMap& env) const {
    const int W = env.width(), H = env.height();
    auto rect = [&](double u0, double u1, double v0, double v1) {  // 0 <= u0 < u1 <= 1
      double acc = 0.0;
      for (int j = std::max(0, int(v0 * H)); j < std::min(H, int(std::ceil(v1 * H))); ++j) {
        const double ov = std::min(v1, double(j + 1) / H) - std::max(v0, double(j) / H);
        if (ov <= 0) continue;
        for (int i = std::max(0, int(u0 * W)); i < std::min(W, int(std::ceil(u1 * W))); ++i) {
          const double ou = std::min(u1, double(i + 1) / W) - std::max(u0, double(i) / W);
          if (ou > 0) acc += ou * ov * env.pdf_uv_texel(i, j);
        }
      }
      return acc;
    };
    std::vector<double> out(count(), 0.0);
    const double rot = env.rotation_deg() * kPi / 180.0;
    for (int a = 0; a < n_cos; ++a) {
      const double v0 = std::acos(std::min(1.0, -1.0 + 2.0 * (a + 1) / n_cos)) / kPi;
      const double v1 = std::acos(std::max(-1.0, -1.0 + 2.0 * a / n_cos)) / kPi;
      for (int b = 0; b < n_phi; ++b) {
        // u = 0.5 − (φ_world − rot)/2π decreases with φ.
        double u0 = 0.5 - (2 * kPi * (b + 1) / n_phi - rot) / (2 * kPi);
        u0 -= std::floor(u0);
        const double u1 = u0 + 1.0 / n_phi;
        out[a * n_phi + b] = u1 <= 1.0 ? rect(u0, u1, v0, v1) : rect(u0, 1.0, v0, v1) + rect(0.0, u1 - 1.0, v0, v1);
      }
    }
    return out;
  }
};

// Chi-square of env.sample() against expected bin probabilities.
test::ChiSquareResult chi_square_env(const EnvironmentMap& env, const std::vector<double>& probability, int n_samples,
                                     uint32_t seed) {
  DirBins bins;
  std::vector<double> observed(bins.count(), 0.0);
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < n_samples; ++k) {
    EnvSample s = env.sample({U(rng), U(rng)});
    if (s.pdf > 0) observed[bins.bin(s.dir)] += 1.0;
  }
  std::vector<double> expected = probability;
  for (double& e : expected) e *= n_samples;
  return test::chi_square(observed, expected);
}

}  // namespace

TEST(EnvironmentMap, ConventionIsBlenderEquirectangularWithZUp) {
  EnvironmentMap env = EnvironmentMap::from_image(make_image(16, 8));
  auto near = [](glm::dvec3 a, glm::dvec3 b) { return glm::length(a - b) < 1e-12; };
  EXPECT_TRUE(near(env.uv_to_direction({0.5, 0.0}), {0, 0, 1}));   // top row: +Z
  EXPECT_TRUE(near(env.uv_to_direction({0.3, 1.0}), {0, 0, -1}));  // bottom row: −Z
  EXPECT_TRUE(near(env.uv_to_direction({0.5, 0.5}), {1, 0, 0}));   // centre: +X
  EXPECT_TRUE(near(env.uv_to_direction({0.25, 0.5}), {0, 1, 0}));  // +Y left of centre
  EXPECT_TRUE(near(env.uv_to_direction({0.75, 0.5}), {0, -1, 0}));
  EXPECT_TRUE(near(env.uv_to_direction({0.0, 0.5}), {-1, 0, 0}));
  const glm::dvec2 uv = env.direction_to_uv({0, 1, 0});
  EXPECT_NEAR(uv.x, 0.25, 1e-12);
  EXPECT_NEAR(uv.y, 0.5, 1e-12);
  // Round trip away from the poles and the seam.
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> U(0.001, 0.999);
  for (int k = 0; k < 1000; ++k) {
    const glm::dvec2 a(U(rng), U(rng));
    const glm::dvec2 b = env.direction_to_uv(env.uv_to_direction(a));
    ASSERT_NEAR(a.x, b.x, 1e-9);
    ASSERT_NEAR(a.y, b.y, 1e-9);
  }
}

TEST(EnvironmentMap, BrightTexelAppearsWhereDocumentedAndRotatesRightHandedAboutZ) {
  // 8×4 map, one bright texel at column 2, row 1: centre (u, v) = (2.5/8, 1.5/4)
  // → θ = 0.375π, φ = π − 2π·0.3125 = 0.375π: above the horizon, between +X and +Y.
  Image img = make_image(8, 4);
  img.at(2, 1, 0) = 10.0f;
  img.at(2, 1, 1) = 5.0f;
  img.at(2, 1, 2) = 1.0f;
  const auto dir = [](double theta, double phi) {
    return glm::dvec3(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  };
  const glm::dvec3 d0 = dir(0.375 * kPi, 0.375 * kPi);
  const std::filesystem::path file = test::temp_dir("light_env") / "spot.exr";
  write_image(file, img);
  EnvironmentMap env = EnvironmentMap::load(file, 2.0, 0.0);
  EXPECT_NEAR(env.radiance(d0).x, 20.0, 1e-4);  // at the texel centre: the texel × scale
  EXPECT_NEAR(env.radiance(d0).y, 10.0, 1e-4);
  EXPECT_NEAR(env.radiance(d0).z, 2.0, 1e-4);
  // The same direction mirrored across the XZ plane is dark (u runs clockwise).
  EXPECT_EQ(env.radiance(dir(0.375 * kPi, -0.375 * kPi)).x, 0.0);
  // rotation_deg 90: the spot turns counter-clockwise seen from above, to φ + 90°.
  EnvironmentMap rot = EnvironmentMap::load(file, 2.0, 90.0);
  EXPECT_NEAR(rot.radiance(dir(0.375 * kPi, 0.875 * kPi)).x, 20.0, 1e-4);
  EXPECT_NEAR(rot.radiance(d0).x, 0.0, 1e-9);
  // Sampling finds it: every sample lies in the texel or the 3×3 neighbours its
  // bilinear light reaches, most in the texel itself.
  int own = 0;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < 1000; ++k) {
    EnvSample s = rot.sample({U(rng), U(rng)});
    const glm::dvec2 uv = rot.direction_to_uv(s.dir);
    const int i = int(uv.x * 8), j = int(uv.y * 4);
    ASSERT_LE(std::abs(i - 2), 1) << uv.x;
    ASSERT_LE(std::abs(j - 1), 1) << uv.y;
    own += (i == 2 && j == 1);
  }
  EXPECT_GT(own, 400);
}

TEST(EnvironmentMap, PdfIntegratesToOneOverTheSphere) {
  EnvironmentMap env = EnvironmentMap::from_image(test_map(64, 32), 1.5, 37.0);
  ASSERT_TRUE(env.has_distribution());
  double sum_uv = 0.0;
  for (int j = 0; j < env.height(); ++j)
    for (int i = 0; i < env.width(); ++i) sum_uv += env.pdf_uv_texel(i, j);
  EXPECT_NEAR(sum_uv / (env.width() * env.height()), 1.0, 1e-6);
  DirBins bins;
  double total = 0.0;
  for (double p : bins.integrate([&](const glm::dvec3& d) { return env.pdf(d); }, env, 8)) total += p;
  EXPECT_NEAR(total, 1.0, 1e-6);
}

TEST(EnvironmentMap, SamplesFollowThePdfChiSquare) {
  EnvironmentMap env = EnvironmentMap::from_image(test_map(64, 32), 1.0, 37.0);
  DirBins bins;
  // Expected counts from the sampling density integrated exactly over each bin.
  const std::vector<double> exact = bins.exact(env);
  double total = 0.0;
  for (double p : exact) total += p;
  EXPECT_NEAR(total, 1.0, 1e-9);
  for (uint32_t seed : {11u, 12u, 13u}) {
    test::ChiSquareResult r = chi_square_env(env, exact, 200000, seed);
    std::printf("environment chi-square (seed %u): %s\n", seed, r.summary().c_str());
    EXPECT_GT(r.p_value, 0.001) << r.summary();
  }
  // ... and from pdf(dir) integrated numerically: the two must agree, which
  // ties pdf() (its 1/(2π² sinθ) and its rotation) to the sampler.
  const std::vector<double> numeric = bins.integrate([&](const glm::dvec3& d) { return env.pdf(d); }, env);
  for (int b = 0; b < bins.count(); ++b) ASSERT_NEAR(numeric[b], exact[b], 1e-4 * exact[b] + 1e-9) << "bin " << b;
  // The harness can fail: against the pdf without its rotation, or without
  // the 1/sin θ of dω = 2π² sin θ du dv, the same samples are rejected.
  EnvironmentMap unrotated = EnvironmentMap::from_image(test_map(64, 32), 1.0, 0.0);
  test::ChiSquareResult wrong_rot = chi_square_env(env, bins.exact(unrotated), 200000, 11);
  EXPECT_LT(wrong_rot.p_value, 1e-6) << wrong_rot.summary();
  std::vector<double> no_sin = bins.integrate(
      [&](const glm::dvec3& d) { return env.pdf(d) * std::sqrt(std::max(0.0, 1.0 - d.z * d.z)) * kPi / 2.0; }, env);
  test::ChiSquareResult wrong_sin = chi_square_env(env, no_sin, 200000, 11);
  EXPECT_LT(wrong_sin.p_value, 1e-6) << wrong_sin.summary();
}

TEST(EnvironmentMap, SampledPdfAndRadianceEqualTheLookups) {
  EnvironmentMap env = EnvironmentMap::from_image(test_map(64, 32), 3.0, -120.0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < 20000; ++k) {
    EnvSample s = env.sample({U(rng), U(rng)});
    ASSERT_GT(s.pdf, 0.0);
    ASSERT_NEAR(glm::length(s.dir), 1.0, 1e-12);
    ASSERT_NEAR(env.pdf(s.dir), s.pdf, 1e-9 * s.pdf) << k;
    const glm::dvec3 L = env.radiance(s.dir);
    ASSERT_NEAR(L.x, s.radiance.x, 1e-9 * (1 + L.x));
    ASSERT_NEAR(L.y, s.radiance.y, 1e-9 * (1 + L.y));
    ASSERT_NEAR(L.z, s.radiance.z, 1e-9 * (1 + L.z));
  }
}

TEST(EnvironmentMap, UniformMapHasPdfOneOverFourPi) {
  Image img = make_image(128, 64);
  for (float& v : img.rgb) v = 0.5f;
  EnvironmentMap env = EnvironmentMap::from_image(img, 2.0, 10.0);
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  // At a row's centre the pdf is 1/(4π) up to sin(Δθ/2)/(Δθ/2) (the band's
  // sinθ averaged against its centre value): ~1e-4 at 64 rows.
  for (int j = 0; j < env.height(); ++j) {
    const double theta = kPi * (j + 0.5) / env.height();
    const glm::dvec3 d = dir_from(std::cos(theta), 2 * kPi * U(rng));
    ASSERT_NEAR(env.pdf(d) * 4 * kPi, 1.0, 2e-4) << "row " << j;
    EXPECT_NEAR(env.radiance(d).x, 1.0, 1e-6);
  }
  // Averaged over a row's band the pdf is exactly uniform: ∫ pdf dω = Ω / 4π.
  DirBins bins;
  std::vector<double> ints = bins.integrate([&](const glm::dvec3& d) { return env.pdf(d); }, env);
  for (double p : ints) EXPECT_NEAR(p * bins.count(), 1.0, 0.02);
  EXPECT_NEAR(env.power(), 4 * kPi * 1.0, 1e-6 * 4 * kPi);
}

TEST(EnvironmentMap, EveryLitDirectionHasPositivePdf) {
  // One lit texel: bilinear filtering spreads its light half a texel into the
  // 8 neighbours, which must be sampleable too; and a texel 1e-12 as bright as
  // the rest still keeps a nonzero float CDF width.
  Image img = make_image(32, 16);
  img.at(7, 5, 1) = 1.0f;
  img.at(31, 0, 0) = 1e-12f;  // at the seam, top row
  EnvironmentMap env = EnvironmentMap::from_image(img);
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  int lit = 0;
  for (int k = 0; k < 200000; ++k) {
    const glm::dvec2 uv(U(rng), U(rng));
    const glm::dvec3 d = env.uv_to_direction(uv);
    if (color::srgb_luminance(env.radiance(d)) > 0.0) {
      ++lit;
      ASSERT_GT(env.pdf(d), 0.0) << uv.x << " " << uv.y;
    }
  }
  EXPECT_GT(lit, 1000);
  EXPECT_GT(env.pdf_uv_texel(0, 0), 0.0);  // the seam neighbour of the faint texel
  EXPECT_GT(env.pdf_uv_texel(31, 0), 0.0);
  EXPECT_EQ(env.pdf_uv_texel(20, 12), 0.0);
}

TEST(EnvironmentMap, BlackMapOrZeroScaleHasNoDistribution) {
  Image img = make_image(16, 8);
  EnvironmentMap black = EnvironmentMap::from_image(img);
  EXPECT_FALSE(black.has_distribution());
  EXPECT_EQ(black.sample({0.3, 0.6}).pdf, 0.0);
  EXPECT_EQ(black.pdf({0, 0, 1}), 0.0);
  EXPECT_EQ(pack_gpu_environment_header(black).can_sample, 0u);
  for (float& v : img.rgb) v = 1.0f;
  EnvironmentMap off = EnvironmentMap::from_image(img, 0.0);
  EXPECT_FALSE(off.has_distribution());
  EXPECT_EQ(off.radiance({1, 0, 0}).x, 0.0);
  img.at(3, 3, 0) = -1.0f;
  img.at(4, 3, 1) = std::nanf("");
  EnvironmentMap sane = EnvironmentMap::from_image(img);
  EXPECT_EQ(sane.sanitized_texels(), 2u);
  EXPECT_TRUE(sane.has_distribution());
}

TEST(EnvironmentMap, BadFilesAreInputErrorsNamingTheFile) {
  const std::filesystem::path dir = test::temp_dir("light_env_bad");
  const std::filesystem::path missing = dir / "no_such_sky.exr";
  try {
    EnvironmentMap::load(missing);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_sky.exr"), std::string::npos) << e.what();
  }
  const std::filesystem::path text = dir / "sky.exr";
  test::write_file(text, "this is not an image\n");
  try {
    EnvironmentMap::load(text);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sky.exr"), std::string::npos) << e.what();
  }
}

TEST(EnvironmentMap, GeneratedSkyAssetHasItsSunWhereGenSkyPutsIt) {
  const std::filesystem::path file = std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/sky/sky.exr";
  EXPECT_LT(std::filesystem::file_size(file), 1536u * 1024u);
  EnvironmentMap env = EnvironmentMap::load(file);
  EXPECT_EQ(env.width(), 512);
  EXPECT_EQ(env.height(), 256);
  // gen_sky's defaults: sun at elevation 25°, azimuth φ = 140° (counter-clockwise
  // from +X seen from above); sky ~0.1–1 elsewhere, ground ~0.05.
  const double e = 25.0 * kPi / 180.0, a = 140.0 * kPi / 180.0;
  const glm::dvec3 sun(std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e));
  EXPECT_GT(env.radiance(sun).x, 30.0);
  EXPECT_LT(env.radiance({0, 0, 1}).x, 1.0);
  EXPECT_LT(env.radiance({0, 0, -1}).x, 0.1);
  // Importance sampling puts the disc's share of the luminance (~4 %, 2e-3 sr)
  // on it: 20x its share of solid angle.
  int on_sun = 0;
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  for (int k = 0; k < 2000; ++k)
    if (glm::dot(env.sample({U(rng), U(rng)}).dir, sun) > std::cos(3.0 * kPi / 180.0)) ++on_sun;
  EXPECT_GT(on_sun, 40);
}

// A Y-up scene's map: world d is the Z-up map's (d.x, −d.z, d.y), so the top
// row is world +Y; lookups, pdfs and samples all go through the same turn.
TEST(EnvironmentMap, ZenithOnWorldYIsAQuarterTurnAboutX) {
  const EnvironmentMap z_up = EnvironmentMap::from_image(test_map(64, 32), 1.5, 37.0);
  const EnvironmentMap y_up = EnvironmentMap::from_image(test_map(64, 32), 1.5, 37.0, true);
  EXPECT_NEAR(y_up.direction_to_uv({0, 1, 0}).y, 0.0, 1e-12);  // the zenith row
  EXPECT_NEAR(y_up.direction_to_uv({0, -1, 0}).y, 1.0, 1e-12);
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  for (int n = 0; n < 1000; ++n) {
    const glm::dvec3 d = glm::normalize(glm::dvec3(U(rng), U(rng), U(rng)));
    const glm::dvec3 turned(d.x, -d.z, d.y);
    const glm::dvec2 uv = y_up.direction_to_uv(d);
    ASSERT_NEAR(glm::distance(uv, z_up.direction_to_uv(turned)), 0.0, 1e-12);
    ASSERT_NEAR(glm::distance(y_up.uv_to_direction(uv), d), 0.0, 1e-9);  // and back
    ASSERT_NEAR(y_up.pdf(d), z_up.pdf(turned), 1e-9 * z_up.pdf(turned));
    ASSERT_NEAR(glm::distance(y_up.radiance(d), z_up.radiance(turned)), 0.0, 1e-9);
  }
  // The turn is not its own inverse: a map that undid it the wrong way is caught.
  EXPECT_GT(glm::distance(y_up.direction_to_uv({0, 0, 1}), z_up.direction_to_uv({0, 0, 1})), 0.1);
}
