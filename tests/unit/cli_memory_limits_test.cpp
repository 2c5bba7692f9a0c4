// Inputs that would exhaust memory are refused before anything is allocated
// (docs/robustness.md "Limits"): one line naming the file, what it needs and
// what there is, exit 2, no output. Each run is limited with `ulimit -v`, as a
// render farm limits a job, so "what there is" is small and known; without
// the checks these ended in "internal error: std::bad_alloc" (exit 1).
#include <gtest/gtest.h>

#include "render/Checkpoint.h"
#include "render/cpu/CpuRenderer.h"
#include "support/AccumulationChecks.h"
#include "support/VdbScenes.h"

namespace pyrolume {
namespace {
using namespace pyrolume::test;
namespace fs = std::filesystem;

constexpr uint64_t kGiB = uint64_t(1) << 20;  // in KiB, as ulimit -v takes it

class CliMemoryLimits : public ::testing::Test {
 protected:
  void SetUp() override {
    if (address_sanitizer()) GTEST_SKIP() << "ulimit -v and AddressSanitizer do not mix";
  }
};

void expect_refused(const CliResult& r, const std::string& what, const std::vector<std::string>& expect,
                    const fs::path& out) {
  EXPECT_EQ(r.status, 2) << what << ": " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << what << ": " << r.err;
  for (const std::string& e : expect) EXPECT_NE(r.err.find(e), std::string::npos) << what << ": '" << e << "' in " << r.err;
  EXPECT_EQ(r.err.find("bad_alloc"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out)) << what;
}

TEST_F(CliMemoryLimits, ASparseGridWhoseDenseArrayCannotFitIsRefused) {
  auto dir = temp_dir("mem-grid");
  // Two voxels 999 apart: a few hundred bytes of file, a 1002³-texel dense
  // array (1.0e9 texels: 4 GB as float, 2 GB as R16F).
  const fs::path vdb = write_two_voxels_vdb(dir / "cube.vdb", {999, 999, 999});
  write_file(dir / "s.json", R"({"film": {"width": 8, "height": 8, "spp": 1},
    "media": [{"type": "vdb", "file": "cube.vdb", "texture_format": "r16f"}]})");
  for (const char* backend : {"cpu", "vulkan"}) {
    CliResult r = run_cli_with_memory_limit(
        kGiB * 3 / 2, "render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --backend " + backend);
    expect_refused(r, backend,
                   {vdb.string() + ": ", "density", "1002x1002x1002 texels (with downsample 1) need", "host memory",
                    "this process can still allocate", "add \"downsample\": "},
                   dir / "o.exr");
  }
  fs::remove_all(dir);
}

// The same grid as a user writes it (texture_format left out, "auto") is
// kept sparse: it renders on both backends under the limit that refuses its
// dense array (issue 26).
TEST_F(CliMemoryLimits, ASparseGridRendersUnderTheLimitThatRefusesItsDenseArray) {
  auto dir = temp_dir("mem-sparse");
  write_two_voxels_vdb(dir / "cube.vdb", {999, 999, 999});
  write_file(dir / "s.json", R"({"film": {"width": 8, "height": 8, "spp": 1},
    "media": [{"type": "vdb", "file": "cube.vdb"}]})");
  for (const char* backend : {"cpu", "vulkan"}) {
    const fs::path out = dir / (std::string(backend) + ".exr");
    CliResult r = run_cli_with_memory_limit(kGiB * 3 / 2, "render " + q(dir / "s.json") + " -o " + q(out) +
                                                              " --backend " + backend);
    EXPECT_EQ(r.status, 0) << backend << ": " << r.err;
    EXPECT_TRUE(fs::exists(out)) << backend;
  }
  fs::remove_all(dir);
}

// A vdb medium of write_tiles_vdb(level, n) alone, rendered on both backends
// in a process limited to 1.5 GiB: refused in one line holding `expect`
// (after the file's name), with no internal error and no image.
void expect_tiles_refused(const std::string& name, int level, int n, const std::vector<std::string>& expect) {
  auto dir = temp_dir("mem-" + name);
  const fs::path vdb = write_tiles_vdb(dir / (name + ".vdb"), level, n);
  write_file(dir / "s.json", R"({"film": {"width": 8, "height": 8, "spp": 1},
    "media": [{"type": "vdb", "file": ")" + name + R"(.vdb"}]})");
  for (const char* backend : {"cpu", "vulkan"}) {
    CliResult r = run_cli_with_memory_limit(
        kGiB * 3 / 2, "render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --backend " + backend);
    std::vector<std::string> parts = expect;
    parts[0] = "pyrolume: " + vdb.string() + ": " + parts[0];
    expect_refused(r, backend, parts, dir / "o.exr");
    EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err;
  }
  fs::remove_all(dir);
}

// Issue 45: a VDB of a few hundred bytes, one active 4096³ root tile. Kept
// sparse its tile would become 2^27 leaves of voxels: refused before any is
// allocated, on both backends. Without the check it allocated up to the
// limit and ended in "out of memory ... std::bad_alloc", exit 1.
TEST_F(CliMemoryLimits, ARootTileOfA4096CubeIsRefusedBeforeAllocating) {
  expect_tiles_refused("root-tile", 3, 1,
                       {"density grid \"density\": keeping it sparse (134217728 leaves",
                        "68719476736 voxels of them in active tiles", "this process can still allocate"});
}

// Issue 45: a grid whose dense texture does not fit under the limit, so
// "auto" keeps it sparse, and whose sparse tree does not fit either (a
// 1024 x 1024 x 1024 cube of one value, as 512 active 128³ tiles: 2^21
// leaves once voxelized). Without any check it ended in "out of memory: an
// allocation failed (std::bad_alloc)", exit 1 (a denser grid reached
// NanoVDB's "internal error: Pool::Pool malloc failed" instead); with only the
// catch of allocation failures, in "memory ran out while reading it", exit 2,
// after allocating up to the limit.
TEST_F(CliMemoryLimits, AGridWhoseSparseTreeCannotFitEitherIsRefused) {
  expect_tiles_refused("sparse-tree", 2, 8,
                       {"density grid \"density\": keeping it sparse (2097152 leaves",
                        "this process can still allocate", "\"downsample\""});
}

TEST_F(CliMemoryLimits, AnAccumulationThatCannotFitIsRefused) {
  auto dir = temp_dir("mem-accum");
  write_file(dir / "s.json", R"({"film": {"width": 8, "height": 8, "spp": 1}})");
  CliResult r = run_cli_with_memory_limit(
      2 * kGiB, "render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --backend cpu --width 8192 --height 8192");
  expect_refused(r, "8192²", {"film.width x film.height", "8192x8192 pixels need", "can still allocate"}, dir / "o.exr");
  fs::remove_all(dir);
}

TEST_F(CliMemoryLimits, EndlessStreamsAsInputsAreRefused) {
  auto dir = temp_dir("mem-zero");
  struct Case {
    std::string what, scene_file, scene;
  } cases[] = {
      {"scene", "/dev/zero", ""},
      {"OBJ", "s.json", R"({"film": {"width": 8, "height": 8, "spp": 1}, "shapes": [{"mesh": "/dev/zero"}]})"},
      {"texture", "s.json",
       R"({"film": {"width": 8, "height": 8, "spp": 1}, "shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 1, 0]},
           "material": {"diffuse": {"texture": "/dev/zero"}}}]})"},
      {"environment", "s.json", R"({"film": {"width": 8, "height": 8, "spp": 1}, "environment": {"file": "/dev/zero"}})"},
  };
  for (const Case& c : cases) {
    if (!c.scene.empty()) write_file(dir / c.scene_file, c.scene);
    const fs::path scene = c.scene_file == "/dev/zero" ? fs::path("/dev/zero") : dir / c.scene_file;
    CliResult r = run_cli_with_memory_limit(kGiB, "render " + q(scene) + " -o " + q(dir / "o.exr") + " --backend cpu");
    expect_refused(r, c.what, {"pyrolume: /dev/zero: "}, dir / "o.exr");
  }
  fs::remove_all(dir);
}

TEST_F(CliMemoryLimits, AForgedCheckpointHeaderAllocatesNothing) {
  auto dir = temp_dir("mem-ckpt");
  write_file(dir / "s.json", R"({"film": {"width": 8, "height": 8, "spp": 4}})");
  // A header claiming a 16384² CPU accumulation (16 GiB) in a file of a few bytes.
  const uint64_t claimed = CpuRenderer::accumulation_bytes(16384, 16384);
  write_file(dir / "o.exr.checkpoint",
             "pyrolume-checkpoint 2\n{\"backend\":\"cpu\",\"device\":\"x\",\"scene\":\"s.json\",\"scene_hash\":" +
                 std::to_string(scene_fingerprint(dir / "s.json")) +
                 ",\"width\":16384,\"height\":16384,\"seed\":1,\"frame\":0,\"spp\":1,\"spp_target\":4,"
                 "\"payload_bytes\":" +
                 std::to_string(claimed) + "}\nabc");
  CliResult r = run_cli_with_memory_limit(
      kGiB, "render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --backend cpu --resume");
  expect_refused(r, "checkpoint", {(dir / "o.exr.checkpoint").string() + ": truncated checkpoint: the header describes"},
                 dir / "o.exr");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pyrolume
