// `pyrolume render --frames`: VDB sequences from a file pattern, keyframes,
// missing frames, --strict, --skip-existing, and frames that re-render
// bit-identically alone (docs/animation.md). Both backends.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "image/ImageIo.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"

using namespace pyrolume;
using namespace pyrolume::test;
namespace fs = std::filesystem;

namespace {

// A shell of hot smoke that grows with the frame: a different grid size (and
// texture size, majorant grid, temperature range) every frame.
void write_frame(const fs::path& dir, int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "shell_%04d.vdb", frame);
  Lattice l;
  l.voxel = 0.1;
  write_explosion_shell_vdb(dir / name, l, 3.0 + frame, 6.0 + frame, 2.0f, 2000.0f + 300.0f * frame, 700.0f);
}

// The camera moves and the emission fades over the keys; the medium scatters,
// so every pixel's value depends on the RNG.
const char* kSequenceScene = R"({
  "camera": {"position": {"keys": [[1, [0, 0, -4]], [3, [0.5, 0.3, -3.5]]]}, "look_at": [0, 0, 0], "fov_deg": 40},
  "film": {"width": 20, "height": 14, "spp": 4, "seed": 5, "exposure": {"keys": [[1, 0], [3, 1]]}},
  "background": {"rgb": [0.05, 0.05, 0.08]},
  "media": [{"name": "shell", "type": "vdb", "file": "shell_####.vdb", "source": "kelvin",
             "sigma_a": [1, 1, 1], "sigma_s": [2, 2, 2], "g": 0.3,
             "emission": {"scale": {"keys": [[1, 1.0], [3, 0.4]]}}}]
})";

fs::path scene_with_frames(const std::string& tag, std::initializer_list<int> frames) {
  fs::path dir = temp_dir(tag);
  write_file(dir / "seq.json", kSequenceScene);
  for (int f : frames) write_frame(dir, f);
  return dir;
}

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

// Pixel data bit for bit (EXR float32 holds the render's floats exactly).
bool same_pixels(const fs::path& a, const fs::path& b) {
  Image x = read_image(a), y = read_image(b);
  return x.width == y.width && x.height == y.height && x.rgb == y.rgb;
}

int count(const std::string& s, const std::string& what) {
  int n = 0;
  for (size_t at = s.find(what); at != std::string::npos; at = s.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

class Sequence : public ::testing::TestWithParam<std::string> {
 protected:
  std::string backend() const { return " --backend " + GetParam(); }
};

TEST_P(Sequence, PatternRendersEveryFrameAndEachFrameAloneIsBitIdentical) {
  fs::path dir = scene_with_frames("seq", {1, 2, 3});
  CliResult r = run_cli("render " + q(dir / "seq.json") + " --frames 1-3 -o " + q(dir / "out_####.exr") + " --stats " +
                        q(dir / "st_$F4.json") + backend());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("validation"), std::string::npos) << r.err;
  for (int f : {1, 2, 3}) {
    const std::string n = "000" + std::to_string(f);
    ASSERT_TRUE(fs::exists(dir / ("out_" + n + ".exr"))) << f;
    auto stats = nlohmann::json::parse(read_file(dir / ("st_" + n + ".json")));
    EXPECT_EQ(stats["frame"], f);
    EXPECT_EQ(stats["backend"], GetParam());
    EXPECT_GT(stats["load_seconds"].get<double>(), 0.0);
  }
  // One line per frame and the closing line.
  EXPECT_EQ(count(r.out, "\n"), 4) << r.out;
  EXPECT_NE(r.out.find("3 rendered, 0 skipped, 0 missing"), std::string::npos) << r.out;
  // The frames differ (grids, camera, emission scale).
  EXPECT_FALSE(same_pixels(dir / "out_0001.exr", dir / "out_0003.exr"));

  // A farm renders frames alone, in any order: each must match the sequence's.
  for (int f : {3, 2}) {
    CliResult a = run_cli("render " + q(dir / "seq.json") + " --frames " + std::to_string(f) + " -o " +
                          q(dir / "alone_####.exr") + backend());
    ASSERT_EQ(a.status, 0) << a.err;
    const std::string n = "000" + std::to_string(f);
    EXPECT_TRUE(same_pixels(dir / ("alone_" + n + ".exr"), dir / ("out_" + n + ".exr"))) << "frame " << f;
  }
}

TEST_P(Sequence, FrameNumberKeysTheRandomNumbers) {
  // The same grid every frame and no keys: frames differ only by their noise.
  fs::path dir = temp_dir("seq-rng");
  write_frame(dir, 2);
  std::string still = kSequenceScene;
  auto replace = [&](const std::string& from, const std::string& to) { still.replace(still.find(from), from.size(), to); };
  replace("shell_####.vdb", "shell_0002.vdb");
  replace(R"({"keys": [[1, [0, 0, -4]], [3, [0.5, 0.3, -3.5]]]})", "[0, 0, -4]");
  replace(R"({"keys": [[1, 1.0], [3, 0.4]]})", "1.0");
  write_file(dir / "still.json", still);
  CliResult r =
      run_cli("render " + q(dir / "still.json") + " --frames 1-3:2 --variance -o " + q(dir / "s_#.exr") + backend());
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir / "s_1.exr"));
  EXPECT_FALSE(fs::exists(dir / "s_2.exr"));  // step 2
  ASSERT_TRUE(fs::exists(dir / "s_3.exr"));
  Image s1 = read_image(dir / "s_1.exr"), s3 = read_image(dir / "s_3.exr");
  EXPECT_NE(s1.rgb, s3.rgb) << "frames 1 and 3 of a static scene must use different random numbers";
  // ... yet both are the same picture up to noise: the image sums agree
  // within 4 standard errors (each pixel's variance of the mean, summed; at
  // 4 spp the hot shell's sum varies by about 20 % from seed to seed).
  ASSERT_TRUE(s1.has_variance() && s3.has_variance());
  double sum1 = 0, sum3 = 0, var = 0;
  for (size_t i = 0; i < s1.rgb.size(); ++i) {
    sum1 += s1.rgb[i];
    sum3 += s3.rgb[i];
    var += double(s1.variance[i]) + double(s3.variance[i]);
  }
  EXPECT_GT(var, 0.0);
  EXPECT_LE(std::abs(sum1 - sum3), 4.0 * std::sqrt(var)) << "sums " << sum1 << " and " << sum3;
}

TEST_P(Sequence, MissingFrameIsReportedAndWritesNothing) {
  fs::path dir = scene_with_frames("seq-missing", {1, 3});
  CliResult r = run_cli("render " + q(dir / "seq.json") + " --frames 1-3 --allow-missing -o " +
                        q(dir / "out_####.png") + " --stats " + q(dir / "st_####.json") + backend());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(count(r.err, "shell_0002.vdb"), 1) << r.err;
  EXPECT_EQ(count(r.err, "\n"), 1) << r.err;  // one line per missing file
  EXPECT_TRUE(fs::exists(dir / "out_0001.png"));
  EXPECT_FALSE(fs::exists(dir / "out_0002.png"));
  EXPECT_FALSE(fs::exists(dir / "st_0002.json"));
  EXPECT_TRUE(fs::exists(dir / "out_0003.png"));
  EXPECT_TRUE(fs::exists(dir / "st_0003.json"));
  EXPECT_NE(r.out.find("2 rendered, 0 skipped, 1 missing"), std::string::npos) << r.out;

  // By default the other frames are rendered too, and the exit status is 2,
  // so a render farm sees the failure.
  fs::path dflt = scene_with_frames("seq-missing-default", {1, 3});
  CliResult d = run_cli("render " + q(dflt / "seq.json") + " --frames 1-3 -o " + q(dflt / "o_####.png") + backend());
  EXPECT_EQ(d.status, 2) << d.err;
  EXPECT_EQ(count(d.err, "shell_0002.vdb"), 1) << d.err;
  EXPECT_NE(d.err.find("1 frame was not rendered for missing inputs: exit status 2"), std::string::npos) << d.err;
  EXPECT_EQ(count(d.err, "\n"), 2) << d.err;
  EXPECT_TRUE(fs::exists(dflt / "o_0001.png"));
  EXPECT_FALSE(fs::exists(dflt / "o_0002.png"));
  EXPECT_TRUE(fs::exists(dflt / "o_0003.png"));

  // --strict: exit 2 at the first missing frame, nothing after it.
  fs::path strict = scene_with_frames("seq-strict", {1, 3});
  CliResult s = run_cli("render " + q(strict / "seq.json") + " --frames 1-3 --strict -o " + q(strict / "o_####.png") +
                        backend());
  EXPECT_EQ(s.status, 2) << s.err;
  EXPECT_NE(s.err.find("shell_0002.vdb"), std::string::npos) << s.err;
  EXPECT_TRUE(fs::exists(strict / "o_0001.png"));
  EXPECT_FALSE(fs::exists(strict / "o_0002.png"));
  EXPECT_FALSE(fs::exists(strict / "o_0003.png"));
}

TEST_P(Sequence, SkipExistingRendersNothingTheSecondTimeAndResumes) {
  fs::path dir = scene_with_frames("seq-skip", {1, 2, 3});
  const std::string cmd = "render " + q(dir / "seq.json") + " --frames 1-3 --skip-existing -o " +
                          q(dir / "out_####.exr") + backend();
  ASSERT_EQ(run_cli(cmd).status, 0);
  Image before = read_image(dir / "out_0002.exr");
  fs::file_time_type t1 = fs::last_write_time(dir / "out_0001.exr");

  CliResult again = run_cli(cmd);
  ASSERT_EQ(again.status, 0) << again.err;
  EXPECT_NE(again.out.find("0 rendered, 3 skipped"), std::string::npos) << again.out;
  EXPECT_EQ(count(again.err, "skipped"), 3) << again.err;
  EXPECT_EQ(fs::last_write_time(dir / "out_0001.exr"), t1);

  // A run killed after frame 1: frames 2 and 3 are rendered on resume, 1 is not.
  fs::remove(dir / "out_0002.exr");
  fs::remove(dir / "out_0003.exr");
  CliResult resume = run_cli(cmd);
  ASSERT_EQ(resume.status, 0) << resume.err;
  EXPECT_NE(resume.out.find("2 rendered, 1 skipped"), std::string::npos) << resume.out;
  EXPECT_EQ(fs::last_write_time(dir / "out_0001.exr"), t1);
  EXPECT_EQ(read_image(dir / "out_0002.exr").rgb, before.rgb);
}

INSTANTIATE_TEST_SUITE_P(Backends, Sequence, ::testing::Values("vulkan", "cpu"));

// --denoise over a sequence keeps one denoiser (device and pipeline) for all
// frames: each frame's denoised image must still be exactly what
// `pyrolume denoise`, starting afresh, makes of that frame's render.
TEST(SequenceCli, DenoisedFramesMatchDenoisingEachFrameAlone) {
  fs::path dir = scene_with_frames("seq-denoise", {1, 2, 3});
  // --aovs: the raw frames then carry what the guided filter reads.
  CliResult r = run_cli("render " + q(dir / "seq.json") + " --frames 1-3 --variance --aovs --denoise -o " +
                        q(dir / "out_####.exr"));
  ASSERT_EQ(r.status, 0) << r.err;
  for (int f : {1, 2, 3}) {
    const std::string n = "000" + std::to_string(f);
    ASSERT_TRUE(fs::exists(dir / ("out_" + n + ".denoised.exr"))) << f;
    CliResult a = run_cli("denoise " + q(dir / ("out_" + n + ".exr")) + " -o " + q(dir / ("alone_" + n + ".exr")));
    ASSERT_EQ(a.status, 0) << a.err;
    EXPECT_TRUE(same_pixels(dir / ("alone_" + n + ".exr"), dir / ("out_" + n + ".denoised.exr"))) << "frame " << f;
  }
  EXPECT_FALSE(same_pixels(dir / "out_0001.denoised.exr", dir / "out_0003.denoised.exr"));
  fs::remove_all(dir);
}

TEST(SequenceCli, BadInputExitsTwoWithAClearMessage) {
  fs::path dir = scene_with_frames("seq-bad", {1});
  const std::string scene = q(dir / "seq.json");
  struct Case {
    std::string args, expect;
  } cases[] = {
      {"--frames 1-3 -o " + q(dir / "o.exr"), "frame pattern"},
      {"--frames 1-3 -o " + q(dir / "o_####.exr") + " --stats " + q(dir / "st.json"), "frame pattern"},
      {"--frames 3-1 -o " + q(dir / "o_####.exr"), "--frames"},
      {"--frames 1-x -o " + q(dir / "o_####.exr"), "--frames"},
      {"-o " + q(dir / "o.exr"), "media[0].file"},                   // a pattern scene needs --frames
      {"--frames 1 -o " + q(dir / "taken_####.exr"), "taken_0001.exr: is a folder"},  // made below
      {"--skip-existing -o " + q(dir / "o.exr"), "--frames"},
  };
  fs::create_directory(dir / "taken_0001.exr");
  for (const Case& c : cases) {
    CliResult r = run_cli("render " + scene + " --backend cpu " + c.args);
    EXPECT_EQ(r.status, 2) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(count(r.err, "\n"), 1) << r.err;
  }
}
