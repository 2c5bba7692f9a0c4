// The CPU reference's accumulation (issue 10): the cases both backends share
// (exact constant radiance at 65 536 spp, non-finite samples counted and
// recorded as 0, bit-identical resume from an interruption or a checkpoint,
// another backend's state refused) run from tests/support/AccumulationSuite.h
// (Accumulation.*/"cpu"); here, the equilibrium medium exact at 65 536 spp, the
// checkpoint file format and the 64-bit sample arithmetic.
#include <gtest/gtest.h>

#include "backends/Backends.h"
#include "render/Checkpoint.h"
#include "render/cpu/CpuRenderer.h"
#include "render/cpu/Rng.h"
#include "shared/gpu_types.h"
#include "support/AccumulationSuite.h"
#include "util/Error.h"

namespace pyrolume {

namespace test {
INSTANTIATE_BACKEND_SUITE(Accumulation, "cpu");
}  // namespace test

namespace {

// An emissive absorbing and scattering medium around the camera is in
// equilibrium: every sample ends in an absorption and returns Le exactly.
TEST(CpuAccumulation, EquilibriumMediumIsExactAt65536Spp) {
  CpuRenderer cpu(2);
  Scene s = test::equilibrium_sphere_scene(4, 4, 65536);
  s.integrator.max_depth = 1000;  // P(a path is cut short) ~ 0.75^1000
  test::expect_constant_radiance_exact(cpu, s, test::equilibrium_radiance(s), 1e-6);
}

// ------------------------------------------------------------ 64-bit totals ----

TEST(SampleCounts, TotalsAre64Bit) {
  // 16384² pixels × 2^24 spp = 2^52: the largest render the limits allow.
  EXPECT_EQ(total_samples(16384, 16384, kMaxSpp), uint64_t(1) << 52);
  // 2^48 (the issue's bar) as 4096² × 2^24 and as 2^14 × 2^10 × 2^24.
  EXPECT_EQ(total_samples(4096, 4096, 1 << 24), uint64_t(1) << 48);
  EXPECT_EQ(total_samples(16384, 1024, 1 << 24), uint64_t(1) << 48);
  // Where a 32-bit product would wrap: 4096 × 4096 × 256 = 2^32.
  EXPECT_EQ(total_samples(4096, 4096, 256), uint64_t(1) << 32);
  // Stats divide doubles: 2^52 is still exact there.
  EXPECT_EQ(double(total_samples(16384, 16384, kMaxSpp)), std::ldexp(1.0, 52));
  // The GPU gets each pass's sample_offset and spp as uint: the largest
  // per-pixel index, kMaxSpp - 1 plus one pass of at most 64, is far from 2^32,
  // and float per-pixel counters (the GPU's non-finite count) stay exact (2^24).
  static_assert(uint64_t(kMaxSpp) + 64 < (uint64_t(1) << 32) && kMaxSpp <= (1 << 24));
}

TEST(SampleCounts, RngStreamsTakeFull64BitSampleIndices) {
  // Sample 2^32 + 5 has its own stream, not sample 5's (no truncation to 32 bits);
  // the same for pixel indices beyond 2^32.
  using cpu::Pcg32;
  Pcg32 a = Pcg32::for_sample(1, 0, 3, 5), b = Pcg32::for_sample(1, 0, 3, (uint64_t(1) << 32) + 5);
  EXPECT_NE(a.next_u32(), b.next_u32());
  Pcg32 c = Pcg32::for_sample(1, 0, 7, 9), d = Pcg32::for_sample(1, 0, (uint64_t(1) << 32) + 7, 9);
  EXPECT_NE(c.next_u32(), d.next_u32());
  // and the same key gives the same stream
  Pcg32 e = Pcg32::for_sample(1, 0, 3, (uint64_t(1) << 40) + 1), f = Pcg32::for_sample(1, 0, 3, (uint64_t(1) << 40) + 1);
  EXPECT_EQ(e.next_u32(), f.next_u32());
}

// ------------------------------------------------------------- checkpoints ----

class CheckpointFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::temp_dir("ckpt");
    test::write_file(dir_ / "s.json", R"({"film": {"width": 4, "height": 2}})");
    id_ = {"cpu", (dir_ / "s.json").string(), scene_fingerprint(dir_ / "s.json"), 4, 2, 9, 0, "CPU"};
    state_.backend = "cpu";
    state_.width = 4;
    state_.height = 2;
    state_.spp = 12;
    state_.data.resize(CpuRenderer::accumulation_bytes(4, 2));
    for (size_t i = 0; i < state_.data.size(); ++i) state_.data[i] = uint8_t(i * 37 + 1);
    file_ = dir_ / "o.exr.checkpoint";
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // The error message of read/check, "" if none.
  std::string read_error() {
    try {
      read_checkpoint(file_);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }

  std::filesystem::path dir_, file_;
  CheckpointIdentity id_;
  AccumulationState state_;
};

TEST_F(CheckpointFile, NameIsOutputPlusCheckpoint) {
  EXPECT_EQ(checkpoint_path("renders/out.exr"), std::filesystem::path("renders/out.exr.checkpoint"));
  EXPECT_EQ(checkpoint_path("a.png"), std::filesystem::path("a.png.checkpoint"));
}

TEST_F(CheckpointFile, RoundTripsExactly) {
  write_checkpoint(file_, id_, 100, state_);
  Checkpoint c = read_checkpoint(file_);
  EXPECT_EQ(c.state.data, state_.data);
  EXPECT_EQ(c.state.spp, 12);
  EXPECT_EQ(c.state.backend, "cpu");
  EXPECT_EQ(c.spp_target, 100);
  EXPECT_EQ(c.identity.scene_hash, id_.scene_hash);
  EXPECT_EQ(c.identity.seed, 9u);
  EXPECT_EQ(c.identity.width, 4);
  EXPECT_NO_THROW(check_resumable(file_, c, id_, 100));
  EXPECT_NO_THROW(check_resumable(file_, c, id_, 12));  // already complete: nothing more to do
}

TEST_F(CheckpointFile, CorruptTruncatedAndForeignFilesAreRefused) {
  write_checkpoint(file_, id_, 100, state_);
  std::string bytes = test::read_file(file_);
  auto rewrite = [&](const std::string& b) { test::write_file(file_, b); };

  std::string flipped = bytes;
  flipped[flipped.size() - 20] ^= 0x10;  // a payload byte
  rewrite(flipped);
  EXPECT_NE(read_error().find("checksum"), std::string::npos) << read_error();

  rewrite(bytes.substr(0, bytes.size() - 3));
  EXPECT_NE(read_error().find("truncated"), std::string::npos) << read_error();
  rewrite(bytes.substr(0, 30));
  EXPECT_NE(read_error().find("truncated"), std::string::npos) << read_error();
  rewrite(bytes + "x");
  EXPECT_NE(read_error().find("trailing"), std::string::npos) << read_error();
  rewrite("P3\n4 2\n255\n");
  EXPECT_NE(read_error().find("not a pyrolume checkpoint"), std::string::npos) << read_error();
  std::filesystem::remove(file_);
  EXPECT_NE(read_error().find("cannot open"), std::string::npos) << read_error();
  // Each message names the file.
  EXPECT_NE(read_error().find(file_.string()), std::string::npos);
}

TEST_F(CheckpointFile, TheChecksumCoversTheHeader) {
  write_checkpoint(file_, id_, 100, state_);
  const std::string bytes = test::read_file(file_);
  // One bit of "spp":12 flipped to "spp":13: a valid header that resumes a
  // render with one spp it does not have. Caught by the checksum.
  const size_t at = bytes.find("\"spp\":12");
  ASSERT_NE(at, std::string::npos) << bytes.substr(0, 300);
  std::string flipped = bytes;
  flipped[at + 7] ^= 0x01;  // '2' -> '3'
  ASSERT_NE(flipped.find("\"spp\":13"), std::string::npos);
  test::write_file(file_, flipped);
  EXPECT_NE(read_error().find(file_.string() + ": corrupt checkpoint: checksum mismatch"), std::string::npos)
      << read_error();
  // The first line too.
  flipped = bytes;
  flipped[0] ^= 0x20;
  test::write_file(file_, flipped);
  EXPECT_NE(read_error().find("not a pyrolume checkpoint"), std::string::npos) << read_error();
}

TEST_F(CheckpointFile, VersionOneFilesAreStillRead) {
  // Version 1: the same layout with "1" and a checksum of the payload alone
  // (FNV-1a 64), as earlier builds wrote it.
  write_checkpoint(file_, id_, 100, state_);
  std::string bytes = test::read_file(file_);
  bytes[std::string("pyrolume-checkpoint ").size()] = '1';
  uint64_t h = 0xcbf29ce484222325ull;
  for (uint8_t b : state_.data) h = (h ^ b) * 0x100000001b3ull;
  for (int i = 0; i < 8; ++i) bytes[bytes.size() - 8 + size_t(i)] = char(uint8_t(h >> (8 * i)));
  test::write_file(file_, bytes);
  const Checkpoint c = read_checkpoint(file_);
  EXPECT_EQ(c.state.data, state_.data);
  EXPECT_EQ(c.state.spp, 12);
}

TEST_F(CheckpointFile, AHeaderClaimingMoreThanTheFileHoldsAllocatesNothing) {
  // 16384² CPU pixels (16 GiB) claimed by a header in a file of a few bytes:
  // refused from the file's size before the payload is allocated (this test
  // would otherwise need 16 GiB).
  write_checkpoint(file_, id_, 100, state_);
  std::string bytes = test::read_file(file_);
  const uint64_t claimed = CpuRenderer::accumulation_bytes(16384, 16384);
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"\"width\":4", "\"width\":16384"},
                                 {"\"height\":2", "\"height\":16384"},
                                 {"\"payload_bytes\":" + std::to_string(state_.data.size()),
                                  "\"payload_bytes\":" + std::to_string(claimed)}}) {
    const size_t at = bytes.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    bytes.replace(at, from.size(), to);
  }
  test::write_file(file_, bytes);
  EXPECT_NE(read_error().find("truncated checkpoint: the header describes " +
                              std::to_string(bytes.find('\n', 30) + 1 + claimed + 8)),
            std::string::npos)
      << read_error();
  // A file of zeros (no line end at all) is read with a bound, not to its end.
  test::write_file(file_, std::string(1 << 20, '\0'));
  EXPECT_NE(read_error().find("not a pyrolume checkpoint"), std::string::npos) << read_error();
}

TEST_F(CheckpointFile, MismatchedRendersAreRefusedNamingTheKey) {
  write_checkpoint(file_, id_, 100, state_);
  const Checkpoint c = read_checkpoint(file_);
  auto refusal = [&](CheckpointIdentity now, int spp) -> std::string {
    try {
      check_resumable(file_, c, now, spp);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  CheckpointIdentity other = id_;
  other.width = 5;
  EXPECT_NE(refusal(other, 100).find(": width: "), std::string::npos) << refusal(other, 100);
  other = id_;
  other.height = 3;
  EXPECT_NE(refusal(other, 100).find(": height: "), std::string::npos);
  other = id_;
  other.seed = 10;
  EXPECT_NE(refusal(other, 100).find(": seed: "), std::string::npos);
  other = id_;
  other.frame = 2;
  EXPECT_NE(refusal(other, 100).find(": frame: "), std::string::npos);
  other = id_;
  other.backend = "vulkan";
  EXPECT_NE(refusal(other, 100).find(": backend: "), std::string::npos);
  other = id_;
  other.scene_hash ^= 1;
  EXPECT_NE(refusal(other, 100).find(": scene: "), std::string::npos);
  EXPECT_NE(refusal(id_, 11).find(": spp: "), std::string::npos) << refusal(id_, 11);
  other = id_;
  other.device = "another GPU";  // informational only
  EXPECT_EQ(refusal(other, 100), "");
}

TEST_F(CheckpointFile, SceneFingerprintIgnoresLayoutButNotValues) {
  const uint64_t h = scene_fingerprint(dir_ / "s.json");
  test::write_file(dir_ / "t.json", "{\n  \"film\" : { \"height\": 2,\n \"width\": 4 } }\n");
  EXPECT_EQ(scene_fingerprint(dir_ / "t.json"), h);
  test::write_file(dir_ / "u.json", R"({"film": {"width": 4, "height": 3}})");
  EXPECT_NE(scene_fingerprint(dir_ / "u.json"), h);
}

}  // namespace
}  // namespace pyrolume
