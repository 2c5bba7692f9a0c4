// The denoiser (host/denoise/Denoiser.h, shaders/denoise.comp) on images with
// known answers, under the validation layers: a flat noisy square stays flat
// at its true value, a sharp edge stays sharp (docs/compositing.md "Denoiser":
// the edge width), the features keep an edge the luminance cannot see, and
// `pyrolume denoise` writes a new file and leaves its input alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "denoise/Denoiser.h"
#include "image/ImageIo.h"
#include "render/vulkan/Context.h"
#include "support/GpuCompute.h"
#include "support/TestSupport.h"
#include "util/Error.h"

using namespace pyrolume;

namespace {

class DenoiseGpu : public ::testing::Test {
 protected:
  void SetUp() override {
    try {
      ctx_ = std::make_unique<vk::Context>(test::validated());
    } catch (const NoDeviceError& e) {
      GTEST_SKIP() << e.what();
    }
    denoiser_ = std::make_unique<Denoiser>(*ctx_);
  }
  void TearDown() override {
    if (ctx_) EXPECT_EQ(ctx_->validation_messages(), 0u) << "Vulkan validation reported problems";
  }
  std::unique_ptr<vk::Context> ctx_;
  std::unique_ptr<Denoiser> denoiser_;
};

// The test images' colour: every value is a level times this.
constexpr float kTint[3] = {1.0f, 0.8f, 0.6f};

// An image whose pixel (x, y) has the true colour truth(x, y) · tint plus
// Gaussian noise of standard deviation sigma(x, y) · tint per channel, and
// that noise's variance as the variance of the mean.
template <class Truth, class Sigma>
Image noisy_image(int w, int h, Truth truth, Sigma sigma, uint32_t seed) {
  Image img = make_image(w, h, true);
  img.alpha.assign(img.pixel_count(), 1.0f);
  std::mt19937 rng(seed);
  std::normal_distribution<float> N(0.0f, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        const float s = sigma(x, y) * kTint[c];
        img.at(x, y, c) = truth(x, y) * kTint[c] + s * N(rng);
        img.var_at(x, y, c) = s * s;
      }
  return img;
}

// The filter at the strength these tests state their bounds for: 3
// iterations (±14 px), σ_l = 1.5. The default (1 iteration, ±2 px) is tuned
// for relMSE on renders and filters less.
DenoiseOptions tested() {
  DenoiseOptions o;
  o.iterations = 3;
  o.sigma_l = 1.5f;
  o.use_features = true;  // off by default; tested here for what they do
  return o;
}

struct Spread {
  double mean = 0.0, sd = 0.0;
  int n = 0;
};
// Mean and standard deviation of channel c over the pixels with keep(x, y).
template <class Keep>
Spread spread(const Image& img, int c, Keep keep) {
  double s = 0.0, s2 = 0.0;
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (keep(x, y)) {
        s += img.at(x, y, c);
        s2 += double(img.at(x, y, c)) * img.at(x, y, c);
        ++n;
      }
  const double m = s / n;
  return {m, std::sqrt(std::max(s2 / n - m * m, 0.0)), n};
}

// The edge tests' image: two noisy halves of levels 1 and 3 (× tint, noise
// σ = 20 % of each level), 256 rows, the edge between columns 47 and 48.
constexpr int kEdgeImageWidth = 96, kEdgeImageRows = 256, kEdgeColumn = 48;
float edge_level(int x) { return x < kEdgeColumn ? 1.0f : 3.0f; }
Image noisy_edge_image() {
  return noisy_image(
      kEdgeImageWidth, kEdgeImageRows, [](int x, int) { return edge_level(x); },
      [](int x, int) { return 0.2f * edge_level(x); }, 7);
}

// The flat-square tests' image: a 96×96 emissive square of value 2 (× tint,
// noise σ = 20 % of it) at [16, 112)² in a 128×128 black, noise-free image.
constexpr int kSquareSize = 128, kSquareLo = 16, kSquareHi = 112;
bool in_square(int x, int y) { return x >= kSquareLo && x < kSquareHi && y >= kSquareLo && y < kSquareHi; }
Image noisy_square_image() {
  return noisy_image(
      kSquareSize, kSquareSize, [](int x, int y) { return in_square(x, y) ? 2.0f : 0.0f; },
      [](int x, int y) { return in_square(x, y) ? 0.4f : 0.0f; }, 25);
}

// Inside the square, 4 px from its sides, the denoised image is flat (its
// spread under a fifth of the input's) and its mean is the true value within
// 4 standard errors of the noisy mean, which must be under 0.25 % (so a 1 %
// bias would be seen). Records each channel's spread ratio as
// `property`_<channel>.
void expect_square_flat(const Image& noisy, const Image& out, const std::string& property) {
  auto interior = [](int x, int y) {
    return x >= kSquareLo + 4 && x < kSquareHi - 4 && y >= kSquareLo + 4 && y < kSquareHi - 4;
  };
  for (int c = 0; c < 3; ++c) {
    const Spread in = spread(noisy, c, interior), den = spread(out, c, interior);
    const double truth = 2.0 * kTint[c], se = in.sd / std::sqrt(double(in.n));
    EXPECT_LT(den.sd, 0.2 * in.sd) << "channel " << c << ": spread " << den.sd << " vs input " << in.sd;
    EXPECT_LT(std::abs(den.mean - truth), 4.0 * se) << "channel " << c << ": mean " << den.mean << " vs " << truth;
    EXPECT_LT(se, 0.005 * truth / 2.0) << "not informative at 0.5 %";
    ::testing::Test::RecordProperty(property + "_" + std::to_string(c), std::to_string(den.sd / in.sd));
  }
}

// Every column `edge_width` or more whole pixels from the edge has its mean
// within 4 standard errors (of the noisy column's mean, σ/√rows) of its
// side's true value, and every column 8 px or more from it is denoised
// (spread under a third of the input's). Returns the largest |z| checked.
double expect_edge_holds(const Image& noisy, const Image& out, int edge_width) {
  double worst = 0.0;
  for (int x = 0; x < kEdgeImageWidth; ++x) {
    const int d = x < kEdgeColumn ? kEdgeColumn - 1 - x : x - kEdgeColumn;  // whole pixels between x and the edge
    for (int c = 0; c < 3; ++c) {
      const Spread in = spread(noisy, c, [&](int px, int) { return px == x; });
      const Spread den = spread(out, c, [&](int px, int) { return px == x; });
      const double t = edge_level(x) * kTint[c];
      const double z = (den.mean - t) / (0.2 * t / std::sqrt(double(kEdgeImageRows)));
      if (d >= edge_width) {
        EXPECT_LT(std::abs(z), 4.0) << "column " << x << " (" << d << " px from the edge) channel " << c << ": "
                                    << den.mean << " vs " << t;
        worst = std::max(worst, std::abs(z));
      }
      if (d >= 8) EXPECT_LT(den.sd, in.sd / 3.0) << "column " << x << " channel " << c;
    }
  }
  return worst;
}

}  // namespace

// A 96×96 emissive square (value 2 · tint, noise σ = 20 % of it) on a black,
// noise-free background: inside it, 4 px from its sides, the denoised image
// is flat (its spread under a fifth of the input's) and its mean is the true
// value within 4 standard errors of the noisy mean (SE ≈ 0.23 % here, so a
// 1 % bias would be seen); the background stays (nearly) black.
TEST_F(DenoiseGpu, FlatSquareStaysFlatAtItsValue) {
  const int w = kSquareSize, h = kSquareSize, lo = kSquareLo, hi = kSquareHi;
  const Image noisy = noisy_square_image();
  Image out = denoiser_->run(noisy, tested());
  ASSERT_EQ(out.width, w);
  ASSERT_EQ(out.height, h);
  EXPECT_FALSE(out.has_variance());
  ASSERT_TRUE(out.has_alpha());
  expect_square_flat(noisy, out, "spread_ratio");
  // The noise-free background around the square: the weight between a
  // noise-free pixel and a noisy one is measured against the noisy one's
  // noise, so a trace of the square spreads out (docs/compositing.md
  // "Denoiser", limits): under 2 % of it next to the square, under 1e-4 from
  // 10 px on. Alpha stays 1.
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int d = std::max({lo - x, x - (hi - 1), lo - y, y - (hi - 1)});  // px outside the square
      if (d <= 0) continue;
      for (int c = 0; c < 3; ++c)
        ASSERT_LT(std::abs(out.at(x, y, c)), (d >= 10 ? 1e-4f : 0.02f) * 2.0f * kTint[c]) << x << "," << y;
      ASSERT_FLOAT_EQ(out.alpha[size_t(y) * w + x], 1.0f);
    }
}

// Two noisy halves, 1 and 3 (× tint, noise σ = 20 % of each): every column
// more than kEdgeWidth = 4 px from the edge has its mean within 4 standard
// errors (of the noisy column's mean, σ/√rows) of its side's true value, and
// is denoised (spread under a third of the input's from 8 px on).
TEST_F(DenoiseGpu, SharpEdgeStaysSharp) {
  constexpr int kEdgeWidth = 4;
  const Image noisy = noisy_edge_image();
  const Image out = denoiser_->run(noisy, tested());
  RecordProperty("worst_z_beyond_edge_width", std::to_string(expect_edge_holds(noisy, out, kEdgeWidth)));
}

// Two surfaces of the same noisy brightness level... almost: 1 and 1.3 (noise
// σ = 0.3, so the luminance alone barely tells them apart), with albedos 0.2
// and 0.8. With the features the edge holds 2 px from it; without them it
// blurs further.
TEST_F(DenoiseGpu, AlbedoKeepsAnEdgeTheLuminanceCannotSee) {
  const int w = 64, h = 256, edge = 32;
  auto truth = [&](int x, int) { return x < edge ? 1.0f : 1.3f; };
  Image noisy = noisy_image(w, h, truth, [&](int, int) { return 0.3f; }, 11);
  noisy.aovs.emission.assign(noisy.pixel_count() * 3, 0.0f);
  noisy.aovs.scatter = noisy.aovs.background = noisy.aovs.emission;
  noisy.aovs.surface = noisy.rgb;
  noisy.aovs.albedo.resize(noisy.pixel_count() * 3);
  noisy.aovs.normal.resize(noisy.pixel_count() * 3);
  noisy.aovs.depth.assign(noisy.pixel_count(), 5.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 3; ++c) {
        noisy.aovs.albedo[noisy.index(x, y, c)] = x < edge ? 0.2f : 0.8f;
        noisy.aovs.normal[noisy.index(x, y, c)] = c == 2 ? 1.0f : 0.0f;
      }
  DenoiseOptions without = tested();
  without.use_features = false;
  const Image with_f = denoiser_->run(noisy, tested()), without_f = denoiser_->run(noisy, without);
  auto column_error = [&](const Image& img, int x) {
    return std::abs(spread(img, 1, [&](int px, int) { return px == x; }).mean - truth(x, 0) * 0.8);
  };
  const double se = 0.3 * 0.8 / std::sqrt(double(h));
  double leak_with = 0.0, leak_without = 0.0;
  for (int x : {edge - 3, edge - 4, edge + 2, edge + 3}) {
    EXPECT_LT(column_error(with_f, x), 4.0 * se) << "column " << x;
    leak_with = std::max(leak_with, column_error(with_f, x));
    leak_without = std::max(leak_without, column_error(without_f, x));
  }
  EXPECT_GT(leak_without, 2.0 * leak_with) << "the features made no difference";
  RecordProperty("leak_with_features", std::to_string(leak_with));
  RecordProperty("leak_without_features", std::to_string(leak_without));
}

// The guided filter (renders with --aovs carry the guide): the image's light
// in one layer (`emission` for media, `surface` for surfaces), the features
// of that kind (media: albedo, normal and depth 0; surfaces: albedo 0.5, the
// normal +Z, depth 5), and the guide as a render writes it: the expected
// emission (noise-free, the truth for a medium, 0 for a surface) and alpha.
enum class Layer { Emission, Surface };
void add_guided_aovs(Image& img, Layer layer, const std::vector<float>& truth) {
  const size_t n = img.pixel_count();
  const std::vector<float> zero(n * 3, 0.0f);
  img.aovs.emission = img.aovs.scatter = img.aovs.surface = img.aovs.background = zero;
  (layer == Layer::Emission ? img.aovs.emission : img.aovs.surface) = img.rgb;
  img.aovs.albedo.assign(n * 3, layer == Layer::Surface ? 0.5f : 0.0f);
  img.aovs.normal = zero;
  if (layer == Layer::Surface)
    for (size_t i = 0; i < n; ++i) img.aovs.normal[i * 3 + 2] = 1.0f;
  img.aovs.depth.assign(n, layer == Layer::Surface ? 5.0f : 0.0f);
  img.aovs.guide = layer == Layer::Emission ? truth : zero;
  img.aovs.guide_alpha.assign(n, 1.0f);
}

// The guided filter keeps a flat emissive square flat at its value (as
// FlatSquareStaysFlatAtItsValue, at the default settings): the ratio
// estimator takes its structure from the guide, so the black, noise-free
// background around it stays exactly black (the guide is 0 there), however
// close to the square.
TEST_F(DenoiseGpu, GuidedFlatSquareStaysFlatAtItsValue) {
  Image noisy = noisy_square_image();
  std::vector<float> truth(noisy.pixel_count() * 3);
  for (int y = 0; y < noisy.height; ++y)
    for (int x = 0; x < noisy.width; ++x)
      for (int c = 0; c < 3; ++c) truth[noisy.index(x, y, c)] = in_square(x, y) ? 2.0f * kTint[c] : 0.0f;
  add_guided_aovs(noisy, Layer::Emission, truth);
  const Image out = denoiser_->run(noisy, DenoiseOptions{});
  expect_square_flat(noisy, out, "guided_spread_ratio");
  for (int y = 0; y < out.height; ++y)
    for (int x = 0; x < out.width; ++x)
      if (!in_square(x, y))
        for (int c = 0; c < 3; ++c) ASSERT_EQ(out.at(x, y, c), 0.0f) << x << "," << y;
}

// Two noisy halves, 1 and 3 (× tint, σ = 20 %), through the guided filter:
// in the emission layer, with the guide's edge, every column's mean is its
// side's true value within 4 standard errors right up to the edge; in the
// surface layer (same albedo, normal and depth on both sides: only the noisy
// luminance tells them apart), from kEdgeWidth = 4 px on, as the unguided
// filter's edge (SharpEdgeStaysSharp). Both are denoised from 8 px on
// (spread under a third of the input's).
TEST_F(DenoiseGpu, GuidedSharpEdgeStaysSharp) {
  for (const Layer layer : {Layer::Emission, Layer::Surface}) {
    const int edge_width = layer == Layer::Emission ? 0 : 4;
    SCOPED_TRACE(layer == Layer::Emission ? "emission" : "surface");
    Image noisy = noisy_edge_image();
    std::vector<float> exact(noisy.pixel_count() * 3);
    for (int y = 0; y < noisy.height; ++y)
      for (int x = 0; x < noisy.width; ++x)
        for (int c = 0; c < 3; ++c) exact[noisy.index(x, y, c)] = edge_level(x) * kTint[c];
    add_guided_aovs(noisy, layer, exact);
    const Image out = denoiser_->run(noisy, DenoiseOptions{});
    RecordProperty(std::string(layer == Layer::Emission ? "emission" : "surface") + "_worst_z",
                   std::to_string(expect_edge_holds(noisy, out, edge_width)));
  }
}

// The CLI: a new file with the denoised RGB and alpha and no variance; the
// input is left as it was.
TEST_F(DenoiseGpu, CliWritesANewFileAndLeavesTheInput) {
  auto dir = test::temp_dir("denoisecli");
  Image noisy = noisy_image(32, 16, [](int, int) { return 1.0f; }, [](int, int) { return 0.2f; }, 3);
  write_image(dir / "in.exr", noisy);
  const std::string before = test::read_file(dir / "in.exr");
  test::CliResult r = test::run_cli("denoise " + (dir / "in.exr").string() + " -o " + (dir / "out.exr").string());
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(test::read_file(dir / "in.exr"), before);
  Image out = read_image(dir / "out.exr");
  EXPECT_EQ(out.width, 32);
  EXPECT_FALSE(out.has_variance());
  EXPECT_TRUE(out.has_alpha());
  EXPECT_LT(spread(out, 0, [](int, int) { return true; }).sd, 0.1);  // the input's is 0.2
  std::filesystem::remove_all(dir);
}

namespace {
// `img` with every radiance value (RGB, light layers, guide) times `k` and
// its variance times k², in single precision as an EXR would hold them (a
// variance past 3.4e38 becomes infinite there too).
Image scaled(Image img, double k) {
  auto times = [](std::vector<float>& v, double f) {
    for (float& x : v) x = float(double(x) * f);
  };
  times(img.rgb, k);
  times(img.variance, k * k);
  for (std::vector<float>* layer : {&img.aovs.emission, &img.aovs.scatter, &img.aovs.surface, &img.aovs.background,
                                    &img.aovs.guide})
    times(*layer, k);
  return img;
}

size_t nonfinite_values(const Image& img) {
  size_t n = 0;
  for (float v : img.rgb) n += !std::isfinite(v);
  for (float v : img.alpha) n += !std::isfinite(v);
  return n;
}
}  // namespace

// Radiance near the top of single precision: the filter's squares and sums
// overflowed (the guided filter returned NaN everywhere from ~1e20, the plain
// one at 3e38). It now filters in a normalised range: the output is finite
// everywhere and is the input's result at that scale. A flat 3e38 image stays
// 3e38; the noisy square at 2^60 (its variance still finite) is denoised as
// at 1 (expect_square_flat after dividing the scale back out); at 2^70 and
// 2^126 (its variance past single precision, so read as unknown, 0) it is
// finite and keeps its mean.
TEST_F(DenoiseGpu, HugeRadianceIsFilteredFinite) {
  for (const bool guided : {false, true}) {
    SCOPED_TRACE(guided ? "guided" : "plain");
    const DenoiseOptions options = guided ? DenoiseOptions{} : tested();
    // The guided filter's layers: all emission, guided by the truth.
    auto with_guide = [&](Image img, const std::vector<float>& truth) {
      if (guided) add_guided_aovs(img, Layer::Emission, truth);
      return img;
    };
    // Flat 3e38 (× tint), variance 1e30: every output value within 1e-5 of it.
    Image flat = noisy_image(32, 32, [](int, int) { return 3e38f; }, [](int, int) { return 0.0f; }, 5);
    flat.variance.assign(flat.variance.size(), 1e30f);
    const Image flat_out = denoiser_->run(with_guide(flat, flat.rgb), options);
    ASSERT_EQ(nonfinite_values(flat_out), 0u);
    for (size_t i = 0; i < flat_out.rgb.size(); ++i)
      ASSERT_NEAR(flat_out.rgb[i] / flat.rgb[i], 1.0, 1e-5) << "value " << i;

    const Image noisy = noisy_square_image();
    std::vector<float> truth(noisy.pixel_count() * 3);
    for (int y = 0; y < noisy.height; ++y)
      for (int x = 0; x < noisy.width; ++x)
        for (int c = 0; c < 3; ++c) truth[noisy.index(x, y, c)] = in_square(x, y) ? 2.0f * kTint[c] : 0.0f;
    const Image square = with_guide(noisy, truth);
    auto interior = [](int x, int y) {
      return x >= kSquareLo + 4 && x < kSquareHi - 4 && y >= kSquareLo + 4 && y < kSquareHi - 4;
    };
    for (const int e : {60, 70, 126}) {
      SCOPED_TRACE("scale 2^" + std::to_string(e));
      const double k = std::ldexp(1.0, e);
      const Image out = denoiser_->run(scaled(square, k), options);
      ASSERT_EQ(nonfinite_values(out), 0u);
      const Image back = scaled(out, 1.0 / k);  // exact: a power of two
      if (e == 60) {
        expect_square_flat(square, back, guided ? "guided_2e60" : "plain_2e60");
      } else {
        for (int c = 0; c < 3; ++c) {
          const Spread in = spread(square, c, interior), den = spread(back, c, interior);
          EXPECT_LT(std::abs(den.mean - 2.0 * kTint[c]), 4.0 * in.sd / std::sqrt(double(in.n))) << "channel " << c;
        }
      }
    }
  }
}
