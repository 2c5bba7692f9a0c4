#pragma once
// Backend-independent accumulation checks (issue 10), run by
// tests/unit/cpu_accumulation_test.cpp and tests/vulkan/vulkan_accumulation_test.cpp
// on their backend.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "backends/Backends.h"
#include "render/Backend.h"
#include "render/Checkpoint.h"
#include "shared/gpu_types.h"
#include "support/AccumulationScenes.h"
#include "support/VdbScenes.h"

namespace pyrolume::test {

// A constant-radiance 4×4 render at 65 536 spp: the mean and Σ L²/n of every
// pixel are exact to rel_tol (naive float accumulation over 1024 passes is
// off by ~1e-5; Kahan sums and double sums are not).
inline void expect_constant_radiance_exact(Backend& backend, const Scene& s, glm::dvec3 L, double rel_tol) {
  RenderResult r = backend.render(s, settings_for(s), {});
  ASSERT_EQ(r.spp, 65536);
  EXPECT_EQ(r.nonfinite_samples, 0u);
  const double n = r.spp;
  double worst = 0.0, worst_sq = 0.0;
  for (size_t p = 0; p < size_t(r.width) * r.height; ++p)
    for (int c = 0; c < 3; ++c) {
      worst = std::max(worst, std::abs(r.sum[p * 3 + c] / n - L[c]) / L[c]);
      worst_sq = std::max(worst_sq, std::abs(r.sum_sq[p * 3 + c] / n - L[c] * L[c]) / (L[c] * L[c]));
    }
  EXPECT_LE(worst, rel_tol) << "mean";
  EXPECT_LE(worst_sq, rel_tol) << "sum of squares";
  std::printf("65536 spp: worst relative error of the mean %.3g, of sum L^2 / n %.3g\n", worst, worst_sq);
}

// Non-finite samples are recorded as 0 and counted, exactly.
inline void expect_nonfinite_samples_counted(Backend& backend, const std::filesystem::path& dir) {
  const int W = 8, H = 4, spp = 64;
  const NonfiniteTexturesAllowed allow_inf;
  Scene s = inf_texture_scene(dir, W, H, spp);
  RenderResult r = backend.render(s, settings_for(s), {});
  EXPECT_EQ(r.nonfinite_samples, uint64_t(W / 2) * H * spp);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      for (int c = 0; c < 3; ++c) {
        const double sum = r.sum[(size_t(y) * W + x) * 3 + c], sq = r.sum_sq[(size_t(y) * W + x) * 3 + c];
        ASSERT_TRUE(std::isfinite(sum) && std::isfinite(sq)) << x << "," << y;
        const double expected = x < W / 2 ? 0.0 : s.background[c];  // non-finite samples count as 0
        EXPECT_NEAR(sum / spp, expected, 1e-6) << x << "," << y << " channel " << c;
      }
}

inline void expect_same_sums(const RenderResult& a, const RenderResult& b) {
  EXPECT_EQ(a.spp, b.spp);
  ASSERT_EQ(a.sum.size(), b.sum.size());
  size_t differ = 0;
  for (size_t i = 0; i < a.sum.size(); ++i) differ += a.sum[i] != b.sum[i] || a.sum_sq[i] != b.sum_sq[i];
  EXPECT_EQ(differ, 0u) << "of " << a.sum.size() << " channel sums differ";
  EXPECT_EQ(a.events, b.events);
  EXPECT_EQ(a.density_lookups, b.density_lookups);
  EXPECT_EQ(a.nonfinite_samples, b.nonfinite_samples);
}

// Interrupted after 3 passes and resumed from the state it returned, or from
// the last periodic checkpoint, the render is bit-identical to an
// uninterrupted one: sample streams are indexed by sample number and the
// state is the backend's own accumulation.
// A RenderControl that cancels the render in its n-th pass's progress call
// (the render then stops after that pass); `passes` counts the calls.
struct CancelAfterPasses {
  explicit CancelAfterPasses(int n) {
    control.cancel = &cancel;
    control.progress = [this, n](int, int) {
      if (++passes == n) cancel = true;
    };
  }
  CancelAfterPasses(const CancelAfterPasses&) = delete;
  std::atomic<bool> cancel{false};
  int passes = 0;
  RenderControl control;
};

inline void expect_resume_exact(Backend& backend, const Scene& s) {
  const RenderSettings rs = settings_for(s);
  RenderResult whole = backend.render(s, rs, {});
  ASSERT_EQ(whole.spp, rs.spp);
  EXPECT_TRUE(whole.state.data.empty()) << "a finished render has nothing to checkpoint";

  CancelAfterPasses stop(3);
  RenderResult part = backend.render(s, rs, stop.control);
  ASSERT_TRUE(part.cancelled);
  ASSERT_GT(part.spp, 0);
  ASSERT_LT(part.spp, rs.spp);
  ASSERT_EQ(part.state.spp, part.spp);
  ASSERT_EQ(part.state.backend, backend.name());

  RenderControl resume;
  resume.resume = &part.state;
  RenderResult rest = backend.render(s, rs, resume);
  EXPECT_EQ(rest.resumed_spp, part.spp);
  expect_same_sums(rest, whole);

  // Periodic checkpoints (every pass here), resumed from the last one taken.
  std::vector<AccumulationState> saved;
  RenderControl periodic;
  periodic.checkpoint_seconds = 1e-9;
  periodic.checkpoint = [&](const AccumulationState& st) { saved.push_back(st); };
  RenderResult again = backend.render(s, rs, periodic);
  expect_same_sums(again, whole);  // checkpoints do not disturb the accumulation
  ASSERT_GE(saved.size(), 2u);
  for (size_t i = 1; i < saved.size(); ++i) EXPECT_GT(saved[i].spp, saved[i - 1].spp);
  RenderControl from_checkpoint;
  from_checkpoint.resume = &saved[saved.size() / 2];
  expect_same_sums(backend.render(s, rs, from_checkpoint), whole);
}


// ------------------------------------------------------------- the CLI ----

inline std::string q(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

inline void expect_same_image(const Image& a, const Image& b) {
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  size_t differ = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) differ += a.rgb[i] != b.rgb[i];
  EXPECT_EQ(differ, 0u) << "of " << a.rgb.size() << " values differ";
  ASSERT_EQ(a.variance.size(), b.variance.size());
  differ = 0;
  for (size_t i = 0; i < a.variance.size(); ++i) differ += a.variance[i] != b.variance[i];
  EXPECT_EQ(differ, 0u) << "of " << a.variance.size() << " variance values differ";
}

// A real SIGINT in the middle of a 10 000 spp render (2 500 under ASan; sent
// once the first checkpoint exists): exit 130, the image so far with its spp
// in the EXR header and in the message, the checkpoint beside it; `--resume`
// then completes it, identical to an uninterrupted render, and removes the
// checkpoint.
inline void expect_cli_interrupt_then_resume(const std::string& backend) {
  // The render is interrupted, resumed to the end and rendered whole: under
  // AddressSanitizer (~7x slower) a quarter of the samples keeps the two
  // full renders from being the sanitized run's last 40 s.
  const int spp = address_sanitizer() ? 2500 : 10000;
  const std::string spp_arg = std::to_string(spp);
  auto dir = temp_dir("cli-resume-" + backend);
  write_file(dir / "s.json", kSlowBallJson);
  const auto out = dir / "o.exr", ckpt = dir / "o.exr.checkpoint";
  CliProcess p = start_cli({"render", (dir / "s.json").string(), "-o", out.string(), "--backend", backend,
                            "--spp", spp_arg, "--checkpoint", "0.02", "--variance", "--stats",
                            (dir / "st.json").string()},
                           dir);
  ASSERT_TRUE(wait_for_file(p, ckpt)) << "the render ended before its first checkpoint: " << read_file(p.err);
  kill(p.pid, SIGINT);
  ASSERT_EQ(wait_exit(p), 130) << read_file(p.err);
  const std::string err = read_file(p.err);

  Image part = read_image(out);
  EXPECT_GT(part.spp, 0);
  EXPECT_LT(part.spp, spp);
  EXPECT_EQ(part.spp_target, spp);
  ASSERT_TRUE(part.has_variance());
  const std::string said = "interrupted after " + std::to_string(part.spp) + " of " + spp_arg + " spp";
  EXPECT_NE(err.find(said), std::string::npos) << err;
  EXPECT_NE(err.find(out.string()), std::string::npos) << err;
  EXPECT_NE(err.find("--resume"), std::string::npos) << err;
  auto stats = nlohmann::json::parse(read_file(dir / "st.json"));
  EXPECT_EQ(stats["spp"], part.spp);
  EXPECT_EQ(stats["cancelled"], true);
  ASSERT_TRUE(std::filesystem::exists(ckpt));

  CliResult resumed = run_cli("render " + q(dir / "s.json") + " -o " + q(out) + " --backend " + backend +
                              " --spp " + spp_arg + " --resume --variance --stats " + q(dir / "st2.json"));
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  EXPECT_EQ(resumed.err.find("validation"), std::string::npos) << resumed.err;
  EXPECT_EQ(err.find("validation"), std::string::npos) << err;
  EXPECT_FALSE(std::filesystem::exists(ckpt)) << "a finished render leaves no checkpoint";
  auto stats2 = nlohmann::json::parse(read_file(dir / "st2.json"));
  EXPECT_EQ(stats2["spp"], spp);
  EXPECT_EQ(stats2["resumed_spp"], part.spp);

  CliResult whole = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "u.exr") + " --backend " + backend +
                            " --spp " + spp_arg + " --variance");
  ASSERT_EQ(whole.status, 0) << whole.err;
  Image a = read_image(out), b = read_image(dir / "u.exr");
  EXPECT_EQ(a.spp, spp);
  EXPECT_EQ(a.spp_target, spp);
  expect_same_image(a, b);
  std::filesystem::remove_all(dir);
}

// SIGTERM: the same save, exit 143.
inline void expect_cli_sigterm_saves(const std::string& backend) {
  auto dir = temp_dir("cli-term-" + backend);
  write_file(dir / "s.json", kSlowBallJson);
  const auto out = dir / "o.exr", ckpt = dir / "o.exr.checkpoint";
  CliProcess p = start_cli(
      {"render", (dir / "s.json").string(), "-o", out.string(), "--backend", backend, "--checkpoint", "0.02"}, dir);
  ASSERT_TRUE(wait_for_file(p, ckpt)) << read_file(p.err);
  kill(p.pid, SIGTERM);
  ASSERT_EQ(wait_exit(p), 143) << read_file(p.err);
  Image part = read_image(out);
  EXPECT_GT(part.spp, 0);
  EXPECT_LT(part.spp, 10000);
  EXPECT_NE(read_file(p.err).find("interrupted after " + std::to_string(part.spp)), std::string::npos);
  // The partial image is exactly a render of that many spp (sample-indexed
  // streams; on the GPU the same passes of 64).
  CliResult same = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "again.exr") + " --backend " + backend +
                           " --spp " + std::to_string(part.spp));
  ASSERT_EQ(same.status, 0) << same.err;
  expect_same_image(part, read_image(dir / "again.exr"));
  std::filesystem::remove_all(dir);
}

// A pathologically dense medium: a grid whose one hot voxel (1e7 per unit)
// sets a global majorant that every ray through it steps at, while the rest
// is nearly empty (1e-3), so a ray crossing it takes ~3e7 null collisions and
// a pass never ends on its own (hours). SIGTERM ~1 s in must end the render
// (cancellation inside passes: the CPU polls its tracking loops, the GPU
// dispatches bands that finish well under a second on an idle machine) with
// exit 143, and leave either nothing (no pass finished) or a whole image of
// the passes that did. A render that waited for its pass would still be
// running at the 20-s watchdog, which kills it (exit 137): the exit status
// is the check. How fast it answers is printed, not asserted: a bound in
// seconds failed on a loaded CI machine (9.2 s against 6) without anything
// being wrong, and timings belong in benchmarks.
inline void expect_sigterm_ends_a_pathological_pass(const std::string& backend) {
  auto dir = temp_dir("cli-dense-" + backend);
  write_vdb(dir / "dense.vdb", {make_float_grid("density", Lattice{0.25}, VoxelBox{{0, 0, 0}, {7, 7, 7}},
                                                [](int i, int j, int k) { return i + j + k == 0 ? 1e7f : 1e-3f; })});
  write_file(dir / "s.json", R"({
  "camera": {"position": [0.875, 0.875, -5], "look_at": [0.875, 0.875, 0.875], "up": [0, 1, 0], "fov_deg": 20},
  "film": {"width": 64, "height": 64, "spp": 64},
  "integrator": {"mis": false, "majorant": "global"},
  "media": [{"type": "vdb", "file": "dense.vdb", "sigma_a": [1, 1, 1], "sigma_s": [0, 0, 0]}]})");
  const auto out = dir / "o.exr";
  CliProcess p = start_cli({"render", (dir / "s.json").string(), "-o", out.string(), "--backend", backend}, dir);
  std::this_thread::sleep_for(std::chrono::milliseconds(1000));
  int raw = 0;
  ASSERT_EQ(waitpid(p.pid, &raw, WNOHANG), 0) << "the render ended on its own: " << read_file(p.err);
  const auto t0 = std::chrono::steady_clock::now();
  kill(p.pid, SIGTERM);
  // Waits at most 20 s, then kills it, so a regression fails instead of hanging.
  for (;;) {
    if (waitpid(p.pid, &raw, WNOHANG) == p.pid) break;
    if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(20)) {
      kill(p.pid, SIGKILL);
      waitpid(p.pid, &raw, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("%s: SIGTERM answered in %.3f s\n", backend.c_str(), seconds);
  EXPECT_EQ(exit_status_of(raw), 143) << "after " << seconds << " s: " << read_file(p.err);
  const std::string err = read_file(p.err);
  if (std::filesystem::exists(out)) {
    const Image part = read_image(out);
    EXPECT_GT(part.spp, 0);
    EXPECT_NE(err.find("interrupted after " + std::to_string(part.spp)), std::string::npos) << err;
  } else {
    EXPECT_NE(err.find("interrupted before the first pass finished; nothing is written"), std::string::npos) << err;
  }
  std::filesystem::remove_all(dir);
}

// `pyrolume render --stats` of a plane whose texture holds +Inf on
// `backend`: every sample of the lit 4 × 4 pixels is non-finite; the stats
// count them, one warning says so, and the image written is finite.
inline void expect_cli_reports_nonfinite_samples(const std::string& backend) {
  auto dir = temp_dir("cli-inf-" + backend);
  const NonfiniteTexturesAllowed allow_inf;
  inf_texture_scene(dir, 8, 4, 16);  // writes inf.exr
  write_file(dir / "s.json", inf_texture_scene_json(8, 4, 16));
  CliResult r = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --backend " + backend +
                        " --stats " + q(dir / "st.json"));
  ASSERT_EQ(r.status, 0) << r.err;
  auto stats = nlohmann::json::parse(read_file(dir / "st.json"));
  EXPECT_EQ(stats["nonfinite_samples"], 4 * 4 * 16);
  EXPECT_NE(r.err.find("256 non-finite samples were recorded as 0"), std::string::npos) << r.err;
  Image img = read_image(dir / "o.exr");
  for (float v : img.rgb) EXPECT_TRUE(std::isfinite(v));
  std::filesystem::remove_all(dir);
}

// A checkpoint whose sums hold a NaN or an infinity under a valid checksum
// (forged, or damaged and re-summed): `--resume` refuses it with one line
// naming the file, exit 2, before a device opens; resumed, the value would
// have stayed in its pixel for good. The checkpoint matches the render in
// everything else (scene, backend, size, seed, frame), so only the sums
// refuse it.
inline void expect_nonfinite_checkpoint_refused(const std::string& backend) {
  for (const float bad : {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    SCOPED_TRACE(bad);
    auto dir = temp_dir("cli-nan-ckpt-" + backend);
    write_file(dir / "s.json", kSlowBallJson);  // 4x4, seed 7
    const auto out = dir / "o.exr", ckpt = dir / "o.exr.checkpoint";
    const CheckpointIdentity id{backend, (dir / "s.json").string(), scene_fingerprint(dir / "s.json"), 4, 4, 7, 0, ""};
    AccumulationState state{backend, 4, 4, 4, std::vector<unsigned char>(accumulation_bytes(backend, 4, 4), 0)};
    // The first sum of the last pixel: a double on the CPU, a float on the GPU.
    const size_t at = backend == "cpu" ? (4 * 4 - 1) * 3 * sizeof(double) : (4 * 4 - 1) * sizeof(gpu::AccumTexel);
    if (backend == "cpu") {
      const double v = bad;
      std::memcpy(state.data.data() + at, &v, sizeof v);
    } else {
      std::memcpy(state.data.data() + at, &bad, sizeof bad);
    }
    write_checkpoint(ckpt, id, 8, state);
    CliResult r = run_cli("render " + q(dir / "s.json") + " -o " + q(out) + " --backend " + backend +
                          " --spp 8 --resume");
    EXPECT_EQ(r.status, 2) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find(ckpt.string() + ": corrupt checkpoint: 1 of its accumulated sums are NaN or infinite"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_TRUE(std::filesystem::exists(ckpt)) << "a refused checkpoint is left as it was";
    std::filesystem::remove_all(dir);
  }
}

}  // namespace pyrolume::test
