#pragma once
// The CLI's subcommands, kept out of main.cpp so tests can call them directly.
#include <atomic>
#include <optional>
#include <string>

namespace pyrolume {

struct RenderArgs {
  std::string scene, output, backend = "vulkan", stats;
  std::optional<int> spp, width, height;
  std::optional<uint32_t> seed;
  double time_limit = 0.0;
  bool variance = false;
  // EXR: the light layers and first-hit features (film.aovs; docs/compositing.md "AOVs").
  bool aovs = false;
  // Also write OUT.denoised.EXT (docs/compositing.md "Denoiser"), from the
  // beauty and its variance (computed for it whether or not --variance is given).
  bool denoise = false;
  int device = -1;
  // Sequences (docs/animation.md): "A-B[:step]"; output and stats are then
  // patterns (out_####.exr, stats_####.json), one file per frame.
  std::string frames;
  bool skip_existing = false;  // skip frames whose output exists (resume)
  bool strict = false;         // stop with exit 2 at the first missing input frame
  bool allow_missing = false;  // frames with missing inputs are skipped and the exit status stays 0
  // Checkpoints (render/Checkpoint.h): save OUT.checkpoint every `checkpoint`
  // seconds (0 = only when interrupted); continue from it with `resume`.
  double checkpoint = 0.0;
  bool resume = false;
  // --exposure: stops or "auto", overriding film.exposure for display output
  // (PNG) on every frame; empty = the scene's (docs/view-transform.md).
  std::string exposure;
  // --view: one of film.view's names, overriding film.view for display output
  // (PNG); empty = the scene's (docs/view-transform.md).
  std::string view;
};
int run_render(const RenderArgs& args, const std::atomic<bool>& cancel);

int run_devices(int device);
int run_info(const std::string& file, bool values);

struct BlackbodyArgs {
  double from_k = 0, to_k = 0, step_k = 0;
  std::string mode = "chromaticity", png;
  int observer = 2;
};
int run_blackbody(const BlackbodyArgs& args);

struct CompareArgs {
  std::string a, b;
  std::optional<double> max_relmse, max_outliers;
};
int run_compare(const CompareArgs& args);

// `pyrolume denoise IN -o OUT` (docs/compositing.md "Denoiser"): IN must have
// variance (render --variance); OUT is a new file, never IN.
struct DenoiseArgs {
  std::string input, output;
  int iterations = 1;
  float sigma_l = 1.5f;
  bool features = false;
  bool no_guide = false;  // the plain filter even with the guide (implied by the three above)
  int device = -1;
};
// A SIGINT/SIGTERM (`cancel`) ends it before the output is committed: nothing
// is written (main turns the signal into exit status 130/143).
int run_denoise(const DenoiseArgs& args, const std::atomic<bool>& cancel);

}  // namespace pyrolume
