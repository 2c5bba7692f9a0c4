// `pyrolume render` on the Vulkan backend: the interrupt/checkpoint/resume
// cases both backends share run from tests/support/CliCheckpointSuite.h
// (CliCheckpoint.*/"vulkan"); here, the device-failure path: a lost device or
// exhausted device memory mid-render (injected with PYROLUME_TEST_FAIL_PASS,
// since lavapipe cannot lose a device) saves the accumulation so far, says
// which failure it was and exits 1.
#include <cstdlib>
#include <regex>

#include <gtest/gtest.h>

#include "support/CliCheckpointSuite.h"
#include "support/VdbScenes.h"

namespace pyrolume {

namespace test {
INSTANTIATE_BACKEND_SUITE(CliCheckpoint, "vulkan");
}  // namespace test

namespace {
using namespace pyrolume::test;

// Runs the CLI with PYROLUME_TEST_FAIL_PASS=fault set.
CliResult run_with_fault(const std::string& fault, const std::string& args) {
  setenv("PYROLUME_TEST_FAIL_PASS", fault.c_str(), 1);
  CliResult r = run_cli(args);
  unsetenv("PYROLUME_TEST_FAIL_PASS");
  return r;
}

// `args` with the pass failure `fault` (NAME:N): exit 1, one line naming NAME.
CliResult expect_device_failure(const std::string& fault, const std::string& args) {
  CliResult r = run_with_fault(fault, args);
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find(fault.substr(0, fault.find(':'))), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  return r;
}

TEST(CliDeviceFailure, OutOfDeviceMemorySavesThePassesBeforeAndExits1) {
  auto dir = temp_dir("cli-oom");
  write_file(dir / "s.json", kSlowBallJson);
  const std::string render = "render " + q(dir / "s.json") + " --variance --spp 1000";
  // Pass 3 fails: the two passes of 64 spp before it are read back and saved.
  CliResult r = expect_device_failure("VK_ERROR_OUT_OF_DEVICE_MEMORY:3", render + " -o " + q(dir / "o.exr"));
  EXPECT_NE(r.err.find("128 of 1000 spp"), std::string::npos) << r.err;
  Image part = read_image(dir / "o.exr");
  EXPECT_EQ(part.spp, 128);
  ASSERT_TRUE(std::filesystem::exists(dir / "o.exr.checkpoint"));
  // What was saved is exactly a 128 spp render ...
  CliResult fresh = run_cli(render.substr(0, render.find(" --spp")) + " --spp 128 -o " + q(dir / "f.exr"));
  ASSERT_EQ(fresh.status, 0) << fresh.err;
  expect_same_image(part, read_image(dir / "f.exr"));
  // ... and resumes to the full one.
  CliResult resumed = run_cli(render + " -o " + q(dir / "o.exr") + " --resume");
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_EQ(resumed.err.find("validation"), std::string::npos) << resumed.err;
  CliResult whole = run_cli(render + " -o " + q(dir / "u.exr"));
  ASSERT_EQ(whole.status, 0) << whole.err;
  expect_same_image(read_image(dir / "o.exr"), read_image(dir / "u.exr"));
  std::filesystem::remove_all(dir);
}

TEST(CliDeviceFailure, DeviceLostSavesTheLastHostCopyAndExits1) {
  auto dir = temp_dir("cli-lost");
  write_file(dir / "s.json", kSlowBallJson);
  const std::string render = "render " + q(dir / "s.json") + " --variance";
  // A lost device cannot be read: what is saved is the host copy taken after
  // pass 1 (or pass 2, if a second copy was due by then).
  CliResult r = expect_device_failure("VK_ERROR_DEVICE_LOST:3", render + " --spp 1000 -o " + q(dir / "o.exr"));
  Image part = read_image(dir / "o.exr");
  EXPECT_TRUE(part.spp == 64 || part.spp == 128) << part.spp;
  EXPECT_NE(r.err.find(std::to_string(part.spp) + " of 1000 spp"), std::string::npos) << r.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "o.exr.checkpoint"));
  CliResult fresh = run_cli(render + " --spp " + std::to_string(part.spp) + " -o " + q(dir / "f.exr"));
  ASSERT_EQ(fresh.status, 0) << fresh.err;
  expect_same_image(part, read_image(dir / "f.exr"));

  // Lost in the first pass of the resumed render: what it resumed from is
  // still there to save.
  CliResult again = run_with_fault("VK_ERROR_DEVICE_LOST:1", render + " --spp 1000 --resume -o " + q(dir / "o.exr"));
  EXPECT_EQ(again.status, 1) << again.err;
  EXPECT_EQ(read_image(dir / "o.exr").spp, part.spp);
  EXPECT_TRUE(std::filesystem::exists(dir / "o.exr.checkpoint"));

  // Any other failure of a pass is handled the same way, with its own message.
  CliResult other = run_with_fault("VK_ERROR_UNKNOWN:2", render + " --spp 1000 -o " + q(dir / "x.exr"));
  EXPECT_EQ(other.status, 1) << other.err;
  EXPECT_NE(other.err.find("the device failed: vkQueueSubmit"), std::string::npos) << other.err;
  EXPECT_NE(other.err.find("VK_ERROR_UNKNOWN"), std::string::npos) << other.err;
  EXPECT_EQ(read_image(dir / "x.exr").spp, 64);  // the host copy after pass 1

  // Lost in the first pass: nothing was accumulated, nothing is written.
  CliResult first = run_with_fault("VK_ERROR_DEVICE_LOST:1", render + " --spp 1000 -o " + q(dir / "n.exr"));
  EXPECT_EQ(first.status, 1) << first.err;
  EXPECT_NE(first.err.find("VK_ERROR_DEVICE_LOST"), std::string::npos) << first.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "n.exr"));
  EXPECT_FALSE(std::filesystem::exists(dir / "n.exr.checkpoint"));
  std::filesystem::remove_all(dir);
}

// An accumulation buffer no device allows (16384² × 64 B = 16 GiB > any
// maxStorageBufferRange, a uint32): one line naming the keys, exit 2.
TEST(CliLimitsVulkan, AccumulationLargerThanTheDeviceAllowsIsBadInput) {
  auto dir = temp_dir("cli-big");
  write_file(dir / "s.json", kSlowBallJson);
  CliResult r = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --width 16384 --height 16384");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("film.width x film.height (or --width/--height): 16384x16384"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("this device's"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "o.exr"));
  std::filesystem::remove_all(dir);
}

// A grid wider than the device's maxImageDimension3D, as a dense texture:
// refused by the loader before its dense array exists, naming the grid and the
// downsample that fits. Left to "auto", the same grid is kept sparse and renders.
TEST(CliLimitsVulkan, GridPastTheDevicesTextureLimitIsBadInput) {
  auto dir = temp_dir("cli-wide");
  write_two_voxels_vdb(dir / "wide.vdb", {20000, 1, 1});  // past any GPU's 3D limit (16384 at most today)
  const std::string scene = R"({"film": {"width": 4, "height": 4, "spp": 1},
    "background": {"rgb": [0.1, 0.1, 0.1]},
    "media": [{"name": "wide", "type": "vdb", "file": "wide.vdb", "source": "houdini", "sigma_a": [1, 1, 1], "sigma_s": [0, 0, 0]FORMAT}]})";
  write_file(dir / "s.json", std::regex_replace(scene, std::regex("FORMAT"), ""));
  CliResult kept = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "sparse.exr"));
  EXPECT_EQ(kept.status, 0) << kept.err;
  EXPECT_TRUE(std::filesystem::exists(dir / "sparse.exr"));
  write_file(dir / "s.json", std::regex_replace(scene, std::regex("FORMAT"), R"(, "texture_format": "r16f")"));
  CliResult r = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "o.exr"));
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("wide.vdb: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("20003x4x4 texels (with downsample 1) exceed this device's 3D texture limit"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find("add \"downsample\": "), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "o.exr"));
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pyrolume
