// `pyrolume render --denoise` and `--aovs` as a user runs them: the raw
// output stays as asked (no variance or layers unless asked), the denoised
// image lands next to it as OUT.denoised.EXT, and the AOV layers written to
// the EXR add up to its RGB.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "image/ImageIo.h"
#include "render/vulkan/Context.h"
#include "scene/Scene.h"
#include "support/TestSupport.h"
#include "util/Error.h"

using namespace pyrolume;
using namespace pyrolume::test;

namespace {
const std::string kDenoiseScene = R"({"film": {"width": 24, "height": 16, "spp": 8},
  "camera": {"position": [0, -5, 1.5], "look_at": [0, 0, 0.8]},
  "background": {"rgb": [0.2, 0.3, 0.5]},
  "shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 0, 1]}, "material": {"diffuse": {"rgb": [0.6, 0.6, 0.6]}}}],
  "media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0, 0, 1], "radius": 0.7}},
             "sigma_a": [1, 1, 1], "sigma_s": [1, 1, 1], "emission": {"rgb": [2, 1, 0.4]}}]})";
}  // namespace

TEST(CliRenderDenoise, WritesTheDenoisedImageBesideTheUntouchedRender) {
  auto dir = temp_dir("clirenderdenoise");
  write_file(dir / "s.json", kDenoiseScene);
  const auto out = dir / "out.exr", denoised = dir / "out.denoised.exr";
  CliResult r = run_cli("render " + (dir / "s.json").string() + " -o " + out.string() + " --denoise");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find(denoised.string()), std::string::npos) << "says where the denoised image went: " << r.out;
  const Image raw = read_image(out), clean = read_image(denoised);
  EXPECT_FALSE(raw.has_variance()) << "--denoise must not add variance to the raw output";
  EXPECT_FALSE(raw.has_aovs()) << "--denoise must not add layers to the raw output";
  ASSERT_EQ(clean.width, raw.width);
  ASSERT_EQ(clean.height, raw.height);
  // The denoiser averages: the image means agree, the pixel spread shrinks.
  double m_raw = 0, m_clean = 0;
  for (size_t i = 0; i < raw.rgb.size(); ++i) {
    m_raw += raw.rgb[i];
    m_clean += clean.rgb[i];
  }
  EXPECT_NEAR(m_clean / m_raw, 1.0, 0.1);
  std::filesystem::remove_all(dir);
}

// render --denoise renders the AOVs and their guide for the denoiser (not
// into OUT), so it runs the guided filter; `pyrolume denoise` on a render
// with --aovs does too, unless --no-guide or one of the plain filter's
// settings (--iterations, --sigma-l, --features) asks for the plain one.
// Each says which it ran, and the two give different images.
TEST(CliRenderDenoise, TheGuidedFilterRunsWhereTheGuideIsAndThePlainOneWhenAsked) {
  auto dir = temp_dir("clirenderguide");
  write_file(dir / "s.json", kDenoiseScene);
  CliResult r = run_cli("render " + (dir / "s.json").string() + " -o " + (dir / "a.exr").string() + " --denoise");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("denoised with the guided filter"), std::string::npos) << r.out;
  EXPECT_FALSE(read_image(dir / "a.exr").has_aovs());

  r = run_cli("render " + (dir / "s.json").string() + " -o " + (dir / "b.exr").string() + " --aovs --variance");
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(read_image(dir / "b.exr").aovs.has_guide());
  const std::string in = (dir / "b.exr").string();
  r = run_cli("denoise " + in + " -o " + (dir / "guided.exr").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("the guided filter"), std::string::npos) << r.out;
  for (const std::string flags : {"--no-guide", "--iterations 1", "--sigma-l 1.5", "--features"}) {
    r = run_cli("denoise " + in + " -o " + (dir / "plain.exr").string() + " " + flags);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.out.find("the plain filter"), std::string::npos) << flags << ": " << r.out;
  }
  EXPECT_NE(read_image(dir / "guided.exr").rgb, read_image(dir / "plain.exr").rgb);
  std::filesystem::remove_all(dir);
}

TEST(CliRenderDenoise, AovLayersInTheExrSumToItsRgb) {
  auto dir = temp_dir("clirenderaovs");
  write_file(dir / "s.json", kDenoiseScene);
  const auto out = dir / "out.exr";
  CliResult r = run_cli("render " + (dir / "s.json").string() + " -o " + out.string() + " --aovs");
  ASSERT_EQ(r.status, 0) << r.err;
  const Image img = read_image(out);
  ASSERT_TRUE(img.has_aovs());
  double layer_total[4] = {0, 0, 0, 0};
  for (size_t i = 0; i < img.rgb.size(); ++i) {
    const double sum = double(img.aovs.emission[i]) + img.aovs.scatter[i] + img.aovs.surface[i] + img.aovs.background[i];
    EXPECT_NEAR(sum, img.rgb[i], 1e-5 * std::abs(img.rgb[i]) + 1e-7) << "value " << i;
    layer_total[0] += img.aovs.emission[i];
    layer_total[1] += img.aovs.scatter[i];
    layer_total[2] += img.aovs.surface[i];
    layer_total[3] += img.aovs.background[i];
  }
  for (double t : layer_total) EXPECT_GT(t, 0.0);
  std::filesystem::remove_all(dir);
}

namespace {
// An emissive ball in front of a background: cheap at any size (no
// scattering, one bounce), for the tests that must not wait for a render.
const std::string kCheapScene = R"({"film": {"width": 8, "height": 8, "spp": 1},
  "camera": {"position": [0, 0, -4], "look_at": [0, 0, 0], "fov_deg": 40},
  "background": {"rgb": [0.2, 0.3, 0.5]},
  "media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0, 0, 0], "radius": 1}},
             "sigma_a": [1, 1, 1], "sigma_s": [0, 0, 0], "emission": {"rgb": [2, 1, 0.4]}}]})";

size_t files_in(const std::filesystem::path& dir) {
  return size_t(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()));
}
}  // namespace

// The denoiser's storage-buffer limit follows from the film size, so a film
// past it is refused before the render is spent: one line naming the
// denoised file, exit 2, nothing written, for a single render and a sequence
// on either backend. (Before, the render ran to the end and then failed.)
TEST(CliRenderDenoise, AFilmTooLargeForTheDenoiserIsRefusedBeforeTheRender) {
  VkDeviceSize range = 0;
  try {
    vk::Context ctx(vk::Context::Options{});
    range = std::min<VkDeviceSize>(ctx.properties().limits.maxStorageBufferRange, ctx.max_allocation_size());
  } catch (const NoDeviceError& e) {
    GTEST_SKIP() << e.what();
  }
  // The smallest square film whose vec4 per pixel passes the range.
  const int side = int(std::sqrt(double(range) / 16.0)) + 1;
  if (side > kMaxFilmSide) GTEST_SKIP() << "this device's storage-buffer range takes any film";
  auto dir = temp_dir("clidenoiselimit");
  write_file(dir / "s.json", kCheapScene);
  const std::string size = " --width " + std::to_string(side) + " --height " + std::to_string(side);
  for (const std::string backend : {"cpu", "vulkan"})
    for (const bool sequence : {false, true}) {
      SCOPED_TRACE(backend + (sequence ? " --frames 1-2" : ""));
      const std::string out = (dir / (sequence ? "o_####.exr" : "o.exr")).string();
      const std::string denoised = (dir / (sequence ? "o_0001.denoised.exr" : "o.denoised.exr")).string();
      CliResult r = run_cli("render " + (dir / "s.json").string() + " -o " + out + " --backend " + backend + size +
                            " --denoise" + (sequence ? " --frames 1-2" : ""));
      EXPECT_EQ(r.status, 2) << r.err;
      EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
      EXPECT_NE(r.err.find(denoised + ": " + std::to_string(side) + " x " + std::to_string(side) +
                           " pixels are too many to denoise on this device"),
                std::string::npos)
          << r.err;
      EXPECT_EQ(files_in(dir), 1u) << "only the scene: nothing rendered, nothing written";
    }
  std::filesystem::remove_all(dir);
}

// A sequence commits each frame independently of its denoised copy: when the
// copy of frame 1 cannot be written (here it leads to /dev/full: ENOSPC),
// that is said on one line, frame 1's raw image is kept, frame 2 is rendered
// and denoised, and the run ends with exit status 2. --skip-existing then
// renders again only the frame without its copy. (Before, the raw frame was
// committed together with its copy, so it was lost too, and the run ended.)
TEST(CliRenderDenoise, ASequenceKeepsTheRawFrameWhenItsDenoisedCopyFails) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  auto dir = temp_dir("clidenoiseseq");
  write_file(dir / "s.json", kCheapScene);
  std::filesystem::create_symlink("/dev/full", dir / "o_0001.denoised.exr");
  const std::string base =
      "render " + (dir / "s.json").string() + " -o " + (dir / "o_####.exr").string() + " --backend cpu --denoise --frames 1-2";
  CliResult r = run_cli(base);
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("frame 1: " + (dir / "o_0001.denoised.exr").string() + ": "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find((dir / "o_0001.exr").string() + " is kept"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1 frame has no denoised copy"), std::string::npos) << r.err;
  EXPECT_EQ(read_image(dir / "o_0001.exr").width, 8);
  EXPECT_EQ(read_image(dir / "o_0002.exr").width, 8);
  EXPECT_EQ(read_image(dir / "o_0002.denoised.exr").width, 8);
  EXPECT_TRUE(std::filesystem::is_symlink(dir / "o_0001.denoised.exr"));

  std::filesystem::remove(dir / "o_0001.denoised.exr");
  r = run_cli(base + " --skip-existing");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("1 rendered, 1 skipped"), std::string::npos) << r.out;
  EXPECT_EQ(read_image(dir / "o_0001.denoised.exr").width, 8);
  std::filesystem::remove_all(dir);
}
