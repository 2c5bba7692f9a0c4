// `pyrolume render` end to end, as a user runs it: outputs, stats, closing line,
// interruption.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "image/ImageIo.h"
#include "support/AccumulationScenes.h"
#include "support/TestSupport.h"

using namespace pyrolume;
using namespace pyrolume::test;

namespace {
const char* kCliScene = R"({
  "camera": {"position": [0, 0, -4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 40},
  "film": {"width": 24, "height": 16, "spp": 8, "seed": 3},
  "background": {"rgb": [0.1, 0.1, 0.1]},
  "media": [{"name": "ball", "type": "homogeneous", "bounds": {"sphere": {"center": [0, 0, 0], "radius": 1}},
             "sigma_a": [1, 1, 1], "sigma_s": [0.5, 0.5, 0.5], "g": 0.2, "emission": {"rgb": [1, 0.5, 0.2]}}]
})";
}  // namespace

class CliRender : public ::testing::TestWithParam<std::string> {};

TEST_P(CliRender, WritesExrWithVarianceStatsAndSummary) {
  const std::string backend = GetParam();
  auto dir = temp_dir("render");
  write_file(dir / "s.json", kCliScene);
  CliResult r = run_cli("render " + (dir / "s.json").string() + " -o " + (dir / "o.exr").string() + " --backend " +
                        backend + " --spp 16 --width 20 --height 10 --variance --stats " + (dir / "st.json").string());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("validation"), std::string::npos) << r.err;
  // One closing line on stdout: path, resolution, spp, seconds, Msamples/s, device.
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_NE(r.out.find("20x10, 16 spp"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("Msamples/s"), std::string::npos) << r.out;

  Image img = read_image(dir / "o.exr");
  EXPECT_EQ(img.width, 20);  // CLI flags override the film
  EXPECT_EQ(img.height, 10);
  ASSERT_TRUE(img.has_variance());
  double centre = img.at(10, 5, 0), corner = img.at(0, 0, 0);
  EXPECT_GT(centre, 0.3);                  // the emissive ball fills the centre
  EXPECT_NEAR(corner, 0.1, 1e-6);          // background seen directly, no variance
  EXPECT_GT(img.var_at(10, 5, 0), 0.0);

  auto stats = nlohmann::json::parse(read_file(dir / "st.json"));
  for (const char* key : {"backend", "device", "width", "height", "spp", "seconds", "load_seconds", "samples_per_second",
                          "peak_rss_mb", "density_lookups_per_ray", "lookups_per_second", "events_per_path",
                          "nonfinite_samples"})
    EXPECT_TRUE(stats.contains(key)) << key;
  EXPECT_EQ(stats["backend"], backend);
  EXPECT_EQ(stats["spp"], 16);
  EXPECT_GT(stats["events_per_path"].get<double>(), 0.0);
  EXPECT_EQ(stats["nonfinite_samples"], 0);
  // What the render resolved: no lights to sample here (a homogeneous emitter
  // is not one), so BSDF/phase sampling with the absorption estimator.
  EXPECT_EQ(stats["light_strategy"], "bsdf");
  EXPECT_EQ(stats["emission_estimator"], "absorption");
  std::filesystem::remove_all(dir);
}

TEST_P(CliRender, PngIsSrgbWithExposure) {
  const std::string backend = GetParam();
  auto dir = temp_dir("png");
  // The standard view: exposure, clip, sRGB (the other views have their own tests:
  // tests/unit/image_view_transform_test.cpp).
  std::string standard = kCliScene;
  standard.replace(standard.find("\"seed\": 3"), 9, "\"seed\": 3, \"view\": \"standard\"");
  write_file(dir / "s.json", standard);
  CliResult a = run_cli("render " + (dir / "s.json").string() + " -o " + (dir / "a.png").string() + " --backend " + backend);
  ASSERT_EQ(a.status, 0) << a.err;
  Image img = read_image(dir / "a.png");  // decoded back to linear
  EXPECT_NEAR(img.at(0, 0, 1), 0.1, 0.004);
  // film.exposure = +1 stop doubles the PNG's linear values (EXR stays linear).
  std::string brighter = standard;
  brighter.replace(brighter.find("\"seed\": 3"), 9, "\"seed\": 3, \"exposure\": 1");
  write_file(dir / "b.json", brighter);
  CliResult b = run_cli("render " + (dir / "b.json").string() + " -o " + (dir / "b.png").string() + " --backend " + backend);
  ASSERT_EQ(b.status, 0) << b.err;
  EXPECT_NEAR(read_image(dir / "b.png").at(0, 0, 1), 0.2, 0.006);
  std::filesystem::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Backends, CliRender, ::testing::Values("vulkan", "cpu"));

// SIGINT mid-render: the image so far is saved, the exit status is 130. A
// signal that arrives before the first pass ends leaves nothing to save (tested
// in CliCheckpoint): on a loaded machine start-up can outlast the first wait,
// and the render is then repeated with a longer one (the last must succeed).
// --stats says which majorant grid each grid got on the GPU: the one the
// file writes, else the cost model's (host/volume/MajorantGrid.h). The
// shipped fire keeps the coarsest, one cell per 16³ texels; the CPU, which
// uses global majorants, writes no key.
TEST(CliStats, ReportsEachGridsMajorantCells) {
  auto dir = temp_dir("majorant_stats");
  const std::string fire = (std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/volumes/fire.vdb").string();
  auto render = [&](const std::string& integrator, const std::string& backend) {
    write_file(dir / "s.json", R"({"integrator": {)" + integrator + R"(}, "media": [{"type": "vdb", "file": ")" + fire +
                                   R"("}]})");
    CliResult r = run_cli("render " + (dir / "s.json").string() + " -o " + (dir / "o.exr").string() + " --backend " +
                          backend + " --spp 1 --width 16 --height 16 --stats " + (dir / "st.json").string());
    EXPECT_EQ(r.status, 0) << r.err;
    return nlohmann::json::parse(read_file(dir / "st.json"));
  };
  auto automatic = render("", "vulkan");
  ASSERT_TRUE(automatic.contains("majorant_grids")) << automatic.dump();
  EXPECT_EQ(automatic["majorant_grids"], nlohmann::json::parse("[[6, 9, 6]]")) << automatic.dump();
  auto written = render(R"("majorant_grid": [3, 4, 5])", "vulkan");
  EXPECT_EQ(written["majorant_grids"], nlohmann::json::parse("[[3, 4, 5]]")) << written.dump();
  EXPECT_FALSE(render("", "cpu").contains("majorant_grids"));
  std::filesystem::remove_all(dir);
}

TEST(CliInterrupt, SigintSavesImageAndExits130) {
  auto dir = temp_dir("sigint");
  write_file(dir / "s.json", kCliScene);
  const auto out = dir / "o.exr";
  for (int wait_ms : {2500, 10000, 30000}) {
    CliProcess p = start_cli({"render", (dir / "s.json").string(), "-o", out.string(), "--spp", "10000000", "--width",
                              "64", "--height", "64"},
                             dir);
    std::this_thread::sleep_for(std::chrono::milliseconds(wait_ms));
    kill(p.pid, SIGINT);
    const int status = wait_exit(p);
    const std::string err = read_file(p.err);
    // Too early: before the first pass ended, or before main() set up its handler.
    const bool early = err.find("before the first pass finished") != std::string::npos || status == -1;
    if (!std::filesystem::exists(out) && early && wait_ms < 30000) continue;
    ASSERT_EQ(status, 130) << err;
    ASSERT_TRUE(std::filesystem::exists(out)) << err;
    Image img = read_image(out);
    EXPECT_EQ(img.width, 64);
    EXPECT_GT(img.at(32, 32, 0), 0.3);
    std::filesystem::remove_all(dir);
    return;
  }
}

// No Vulkan driver: one line that points to --backend cpu, exit 2, no output;
// the CPU backend still renders.
TEST(CliNoDevice, PointsToCpuBackend) {
  auto dir = temp_dir("nodev");
  write_file(dir / "s.json", kCliScene);
  const char* old = std::getenv("VK_ICD_FILENAMES");
  std::string saved = old ? old : "";
  setenv("VK_ICD_FILENAMES", "/nonexistent-icd.json", 1);
  CliResult r = run_cli("render " + (dir / "s.json").string() + " -o " + (dir / "o.exr").string());
  CliResult cpu = run_cli("render " + (dir / "s.json").string() + " -o " + (dir / "c.exr").string() + " --backend cpu");
  CliResult devices = run_cli("devices");
  if (old) setenv("VK_ICD_FILENAMES", saved.c_str(), 1);
  else unsetenv("VK_ICD_FILENAMES");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("--backend cpu"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "o.exr"));
  EXPECT_EQ(devices.status, 2) << devices.err;
  EXPECT_EQ(cpu.status, 0) << cpu.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "c.exr"));
  std::filesystem::remove_all(dir);
}
