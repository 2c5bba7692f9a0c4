#pragma once
// Scenes and helpers for the accumulation tests (issue 10: precision, NaN
// accounting, checkpoints, interruption), shared by the CPU (tests/unit) and
// Vulkan (tests/vulkan) suites. Header-only.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "image/ImageIo.h"
#include "support/AnalyticScenes.h"
#include "support/SurfaceScenes.h"
#include "support/TestSupport.h"

namespace pyrolume::test {

// Nothing but a constant background: every sample is exactly `bg`, so the mean
// of any spp is bg and Σ L²/n is bg² (up to the accumulation's rounding).
inline Scene constant_background_scene(int width, int height, int spp, glm::dvec3 bg) {
  Scene s = analytic_base_scene(width, height, spp);
  s.background = bg;
  return s;
}

// A plane whose albedo texture is all +Inf (an EXR can hold it) covers
// exactly the left half of the
// image (world x > 0: image x grows along cross(forward, up) = -x here;
// its edge x = 0 projects onto the centre column boundary for an even
// width); the right half sees the background. Every camera sample that hits
// the plane carries infinite throughput to the background it then escapes to
// (Inf, or NaN where a bilinear weight is 0), so exactly width/2 · height · spp
// samples are non-finite. (A NaN albedo would not do: the walks end a path
// whose throughput is not > 0.)
//
// Texture::load refuses non-finite texels: render it while a
// NonfiniteTexturesAllowed (below) lives.
inline Scene inf_texture_scene(const std::filesystem::path& dir, int width, int height, int spp) {
  Image inf_img = make_image(2, 2);
  for (float& v : inf_img.rgb) v = std::numeric_limits<float>::infinity();
  write_image(dir / "inf.exr", inf_img);
  Scene s = analytic_base_scene(width, height, spp);
  s.background = {0.25, 0.5, 0.75};
  s.integrator.max_depth = 4;
  s.integrator.mis = false;
  Shape plane = plane_shape({50, 0, 0}, {0, 0, -1}, {100, 100}, {1, 1, 1});
  plane.texture = dir / "inf.exr";
  s.shapes.push_back(plane);
  return s;
}

// While one lives, the test hook PYROLUME_TEST_NONFINITE_TEXTURES lets
// non-finite texels through Texture::load, in this process and the CLI runs
// it starts. Scoped: set for the whole process, it made a later test of the
// refusal fail when gtest ran both in one process.
struct NonfiniteTexturesAllowed {
  NonfiniteTexturesAllowed() { setenv("PYROLUME_TEST_NONFINITE_TEXTURES", "1", 1); }
  ~NonfiniteTexturesAllowed() { unsetenv("PYROLUME_TEST_NONFINITE_TEXTURES"); }
  NonfiniteTexturesAllowed(const NonfiniteTexturesAllowed&) = delete;
  NonfiniteTexturesAllowed& operator=(const NonfiniteTexturesAllowed&) = delete;
};

// The same scene as JSON, for CLI runs (the texture path relative to the scene).
inline std::string inf_texture_scene_json(int width, int height, int spp) {
  return R"({
  "camera": {"position": [0, 0, -5], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 40},
  "film": {"width": )" + std::to_string(width) + R"(, "height": )" + std::to_string(height) + R"(, "spp": )" +
         std::to_string(spp) + R"(, "seed": 7},
  "integrator": {"max_depth": 4, "mis": false},
  "background": {"rgb": [0.25, 0.5, 0.75]},
  "shapes": [{"plane": {"center": [50, 0, 0], "normal": [0, 0, -1], "size": [100, 100]},
              "material": {"diffuse": {"rgb": [1, 1, 1], "texture": "inf.exr"}}}]
})";
}

// A 4×4 render that takes about a second at 10 000 spp on one core: a dense,
// high-albedo scattering ball (~25 events per path) in front of a background.
// Long enough to interrupt once the first checkpoint exists, short enough to
// render twice in a test.
inline const char* kSlowBallJson = R"({
  "camera": {"position": [0, 0, -4], "look_at": [0, 0, 0], "up": [0, 1, 0], "fov_deg": 10},
  "film": {"width": 4, "height": 4, "spp": 10000, "seed": 7},
  "integrator": {"max_depth": 256, "mis": false},
  "background": {"rgb": [0.2, 0.3, 0.4]},
  "media": [{"name": "ball", "type": "homogeneous", "bounds": {"sphere": {"center": [0, 0, 0], "radius": 1}},
             "sigma_a": [0.1, 0.1, 0.1], "sigma_s": [20, 20, 20], "g": 0.3, "emission": {"rgb": [1, 0.5, 0.2]}}]
})";

// `pyrolume ARGS...` started in the background (stdout and stderr to files).
struct CliProcess {
  pid_t pid = -1;
  std::filesystem::path out, err;
  int status = -2;  // exit status once reaped; -1: killed by a signal
};

inline CliProcess start_cli(const std::vector<std::string>& args, const std::filesystem::path& dir) {
  CliProcess p{-1, dir / "bg_stdout.txt", dir / "bg_stderr.txt"};
  std::vector<std::string> argv_s{pyrolume_bin()};
  argv_s.insert(argv_s.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_s) argv.push_back(a.data());
  argv.push_back(nullptr);
  p.pid = fork();
  if (p.pid == 0) {
    int o = open(p.out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    int e = open(p.err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(o, 1);
    dup2(e, 2);
    execv(argv_s[0].c_str(), argv.data());
    _exit(99);
  }
  return p;
}

inline int exit_status_of(int raw) { return WIFEXITED(raw) ? WEXITSTATUS(raw) : -1; }

// Waits until `file` exists (the process is then mid-render) or the process
// has ended; true if the file appeared while the process still ran.
inline bool wait_for_file(CliProcess& p, const std::filesystem::path& file) {
  for (;;) {
    if (std::filesystem::exists(file)) return true;
    int raw = 0;
    if (waitpid(p.pid, &raw, WNOHANG) == p.pid) {
      p.status = exit_status_of(raw);
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

inline int wait_exit(CliProcess& p) {
  if (p.status != -2) return p.status;
  int raw = 0;
  waitpid(p.pid, &raw, 0);
  return p.status = exit_status_of(raw);
}

}  // namespace pyrolume::test
