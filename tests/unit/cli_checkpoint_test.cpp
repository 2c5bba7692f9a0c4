// `pyrolume render` on the CPU backend: the interrupt/checkpoint/resume cases
// both backends share run from tests/support/CliCheckpointSuite.h
// (CliCheckpoint.*/"cpu"); here, a mismatched resume refused and limits that
// are bad input.
#include <gtest/gtest.h>

#include "render/Limits.h"
#include "support/CliCheckpointSuite.h"
#include "util/Error.h"

namespace pyrolume {

namespace test {
INSTANTIATE_BACKEND_SUITE(CliCheckpoint, "cpu");
}  // namespace test

namespace {
using namespace pyrolume::test;

TEST(CliCheckpointCpu, MismatchedResumeIsRefused) {
  auto dir = temp_dir("cli-mismatch");
  write_file(dir / "s.json", kSlowBallJson);
  const std::string base = "render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --backend cpu";
  ASSERT_EQ(run_cli(base + " --spp 8 --time-limit 1e-9 --checkpoint 1000").status, 0);  // stops after one pass
  ASSERT_TRUE(std::filesystem::exists(dir / "o.exr.checkpoint"));
  const std::string ckpt = (dir / "o.exr.checkpoint").string();
  struct Case {
    std::string args, key;
  } cases[] = {{" --resume --width 5", ": width: "},
               {" --resume --seed 99", ": seed: "},
               {" --resume --backend vulkan", ": backend: "},
               {" --resume --spp 2", ": spp: "}};
  for (const Case& c : cases) {
    CliResult r = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") +
                          (c.args.find("--backend") == std::string::npos ? " --backend cpu" : "") + c.args);
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(ckpt + c.key), std::string::npos) << r.err;
  }
  // The scene changed (another value): refused too.
  std::string changed = kSlowBallJson;
  changed.replace(changed.find("\"g\": 0.3"), 8, "\"g\": 0.4");
  write_file(dir / "s.json", changed);
  CliResult r = run_cli(base + " --resume");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(ckpt + ": scene: "), std::string::npos) << r.err;
  // A corrupt checkpoint: refused, naming the file.
  write_file(dir / "o.exr.checkpoint", "pyrolume-checkpoint 1\n{\"backend\": \"cpu\"}\n");
  r = run_cli(base + " --resume");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(ckpt + ": corrupt checkpoint"), std::string::npos) << r.err;
  // No checkpoint at all: a warning, then a render from 0 spp.
  std::filesystem::remove(dir / "o.exr.checkpoint");
  r = run_cli(base + " --spp 8 --resume");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("rendering from 0 spp"), std::string::npos) << r.err;
  EXPECT_EQ(read_image(dir / "o.exr").spp, 8);
  std::filesystem::remove_all(dir);
}

// Absurd sizes are one-line errors naming the key, exit 2, and no output.
TEST(CliLimits, AbsurdSizesAreBadInput) {
  auto dir = temp_dir("cli-limits");
  write_file(dir / "s.json", kSlowBallJson);
  const std::string base = "render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --backend cpu";
  struct Case {
    std::string args, needle;
  } cases[] = {{" --width 1e9", "--width"},
               {" --height 1000000000", "--height"},
               {" --spp 1e9", "--spp"},
               {" --spp 16777217", "--spp"},
               {" --checkpoint -1", "--checkpoint"},
               {" --frames 1-2 --resume -o " + q(dir / "o_####.exr"), "--resume"}};
  for (const Case& c : cases) {
    CliResult r = run_cli(c.args.find(" -o ") == std::string::npos
                              ? base + c.args
                              : "render " + q(dir / "s.json") + " --backend cpu" + c.args);
    EXPECT_EQ(r.status, 2) << c.args << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(c.needle), std::string::npos) << r.err;
  }
  for (const char* film : {R"("width": 1000000000)", R"("width": 1e9)", R"("height": 0)", R"("spp": 16777217)",
                           R"("spp": 1e12)"}) {
    std::string scene = kSlowBallJson;
    const std::string key = std::string(film).substr(1, std::string(film).find('"', 1) - 1);
    const size_t at = scene.find("\"" + key + "\": ");
    scene.replace(at, scene.find_first_of(",}", at) - at, film);
    write_file(dir / "b.json", scene);
    CliResult r = run_cli("render " + q(dir / "b.json") + " -o " + q(dir / "o.exr") + " --backend cpu");
    EXPECT_EQ(r.status, 2) << film << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("film." + key), std::string::npos) << r.err;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "o.exr"));
  std::filesystem::remove_all(dir);
}

TEST(Limits, AccumulationSizeIsCheckedIn64Bits) {
  // 16384² pixels × 64 B = 16 GiB: past a 4 GiB limit, though 16384² · 64 wraps to 0 in 32 bits.
  try {
    check_accumulation_size("s.json", 16384, 16384, 64, uint64_t(4) << 30, "the test's limit");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("s.json: film.width x film.height (or --width/--height): 16384x16384"), std::string::npos) << m;
    EXPECT_NE(m.find("16.0 GiB"), std::string::npos) << m;
    EXPECT_NE(m.find("the test's limit (4.0 GiB)"), std::string::npos) << m;
  }
  EXPECT_NO_THROW(check_accumulation_size("s.json", 1024, 1024, 64, uint64_t(64) << 20, "64 MiB"));  // exactly fits
  EXPECT_THROW(check_accumulation_size("s.json", 1024, 1025, 64, uint64_t(64) << 20, "64 MiB"), InputError);
  EXPECT_NO_THROW(check_accumulation_size("s.json", 16384, 16384, 64, 0, "unknown"));  // 0: no limit known
  EXPECT_GT(physical_memory_bytes(), uint64_t(1) << 26);
}

}  // namespace
}  // namespace pyrolume
