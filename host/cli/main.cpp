// pyrolume command line (README.md "Using it"; the scene format: docs/scene-format.md).
// Exit status: 0 ok, 1 internal error, 2 bad input, 3 compare beyond limits,
// 130/143 interrupted (the image so far is saved first).
#include <algorithm>
#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <limits>
#include <new>
#include <string>

#include <malloc.h>
#include <unistd.h>

#include <CLI/CLI.hpp>

#include "cli/Commands.h"
#include "image/AtomicFile.h"
#include "image/DisplayTransform.h"
#include "preview/Preview.h"
#include "render/Render.h"
#include "util/Error.h"
#include "util/Suggest.h"

namespace {
std::atomic<bool> g_cancel{false};
std::atomic<int> g_signal{0};
// The first SIGINT/SIGTERM asks the render to stop (within the pass in
// flight, which is dropped) and save the passes finished; a second one (the
// user will not wait for the save) exits at once with the same status,
// saving nothing more and removing the temp files of a save in progress.
extern "C" void on_signal(int sig) {
  if (g_cancel.exchange(true)) {
    static const char msg[] = "pyrolume: second signal: exiting without saving\n";
    [[maybe_unused]] ssize_t n = write(2, msg, sizeof msg - 1);
    pyrolume::remove_pending_temp_files();
    _exit(128 + sig);
  }
  g_signal = sig;
}

// A positive, finite number of `unit`, at most `max` (the largest float
// where the value is stored as one). CLI11's NonNegativeNumber takes 0 (read
// as "no limit" by --time-limit), PositiveNumber takes nan and inf, and
// neither checks that the whole argument is a number.
CLI::Validator positive_finite(const std::string& unit, double max = std::numeric_limits<double>::max()) {
  return CLI::Validator(
      [unit, max](std::string& text) -> std::string {
        double v = 0.0;
        size_t used = 0;
        try {
          v = std::stod(text, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (text.empty() || used != text.size() || !std::isfinite(v) || !(v > 0.0) || v > max || !(float(v) > 0.0f))
          return "must be a positive, finite number of " + unit + ", got \"" + text + "\"";
        return "";
      },
      "NUMBER>0");
}

// Seconds for --time-limit and --checkpoint.
const CLI::Validator kPositiveSeconds = positive_finite("seconds");

// --exposure: "auto" or stops within ±kMaxExposureStops; '' is refused too.
const CLI::Validator kExposure(
    [](std::string& text) { return pyrolume::exposure_problem(text); }, "EV|auto");

// --view: one of film.view's names; '' is refused too.
const CLI::Validator kView([](std::string& text) { return pyrolume::view_problem(text); }, "NAME");

// " (did you mean ...?)" for the first word on the command line that names
// no subcommand or no flag of its subcommand, "" when there is none.
std::string flag_suggestion(CLI::App& app, int argc, char** argv) {
  if (argc < 2) return "";
  std::vector<std::string> commands;
  for (const CLI::App* sub : app.get_subcommands({})) commands.push_back(sub->get_name());
  CLI::App* sub = nullptr;
  try {
    sub = app.get_subcommand(argv[1]);
  } catch (const CLI::OptionNotFound&) {
    return argv[1][0] == '-' ? "" : pyrolume::did_you_mean(argv[1], commands);
  }
  std::vector<std::string> flags;
  for (const CLI::Option* o : sub->get_options()) {
    for (const std::string& l : o->get_lnames()) flags.push_back("--" + l);
    for (const std::string& n : o->get_snames()) flags.push_back("-" + n);
  }
  for (int i = 2; i < argc; ++i) {
    const std::string word = std::string(argv[i]).substr(0, std::string(argv[i]).find('='));
    if (word.size() < 3 || word.compare(0, 2, "--") != 0) continue;
    if (std::find(flags.begin(), flags.end(), word) == flags.end()) return pyrolume::did_you_mean(word, flags);
  }
  return "";
}
// `pyrolume render`: its options fill `args` when the command line is parsed.
CLI::App* add_render_command(CLI::App& app, pyrolume::RenderArgs& args) {
  using namespace pyrolume;
  CLI::App* render = app.add_subcommand("render", "Render a scene to EXR or PNG");
  render->add_option("scene", args.scene,
                     "Scene JSON file, or a .vdb/.nvdb file (a #### pattern with --frames) as the shortest scene naming it")
      ->required();
  render->add_option("-o,--output", args.output, "Output image (.exr linear float, .png sRGB)");
  render->add_option("--backend", args.backend, "vulkan (default) or cpu")->check(CLI::IsMember({"vulkan", "cpu"}));
  render->add_option("--spp", args.spp, "Samples per pixel (overrides film.spp), at most 2^24")
      ->check(CLI::Range(pyrolume::kMinSpp, pyrolume::kMaxSpp));
  render->add_option("--width", args.width, "Image width (overrides film.width)")->check(CLI::Range(1, pyrolume::kMaxFilmSide));
  render->add_option("--height", args.height, "Image height (overrides film.height)")->check(CLI::Range(1, pyrolume::kMaxFilmSide));
  render->add_option("--seed", args.seed, "Random seed (overrides film.seed)");
  render->add_option("--time-limit", args.time_limit, "Stop after the pass that crosses SEC seconds (SEC > 0)")
      ->check(kPositiveSeconds);
  render->add_option("--stats", args.stats, "Write render statistics as JSON");
  render->add_flag("--variance", args.variance, "EXR: add the per-pixel variance of the mean (variance.R/G/B)");
  render->add_flag("--aovs", args.aovs,
                   "EXR: add the light layers (emission, scatter, surface, background) and the features (albedo, "
                   "normal, depth), as film.aovs does");
  render->add_flag("--denoise", args.denoise,
                   "Also write OUT.denoised.exr (or .png) through the denoiser; OUT itself is left as it is");
  render->add_option("--exposure", args.exposure,
                     "PNG: exposure in stops (within ±30), or auto (overrides film.exposure on every frame; EXR stays "
                     "linear)")
      ->check(kExposure);
  render->add_option("--view", args.view,
                     "PNG: view transform, agx | agx_punchy | filmic | standard (overrides film.view on every frame; "
                     "EXR stays linear)")
      ->check(kView);
  render->add_option("--device", args.device, "Vulkan device index (see `pyrolume devices`)")->check(CLI::NonNegativeNumber);
  render->add_option("--frames", args.frames,
                     "Render frames A-B[:step] (or one frame A); -o and --stats are then patterns: out_####.exr");
  render->add_flag("--skip-existing", args.skip_existing, "With --frames: skip frames whose output exists");
  render->add_flag("--strict", args.strict, "With --frames: stop (exit 2) at the first missing input frame");
  render->add_flag("--allow-missing", args.allow_missing,
                   "With --frames: frames whose input files are missing are skipped and the exit status stays 0 "
                   "(without it the other frames are rendered and the exit status is 2)");
  render->add_option("--checkpoint", args.checkpoint,
                     "Every SEC seconds save the accumulation to OUT.checkpoint (e.g. out.exr.checkpoint; an "
                     "interrupted render always saves it; a finished one removes it)")
      ->check(kPositiveSeconds);
  render->add_flag("--resume", args.resume,
                   "Continue from OUT.checkpoint (same scene, backend, size, seed; refused otherwise) up to --spp");
  return render;
}

// `pyrolume preview`: its options fill `pv`.
CLI::App* add_preview_command(CLI::App& app, pyrolume::PreviewArgs& pv) {
  using namespace pyrolume;
  CLI::App* preview = app.add_subcommand("preview", "Open a window that shows the render converging");
  preview->add_option("scene", pv.scene, "Scene JSON file, or a .vdb/.nvdb file")->required();
  preview->add_option("--frames", pv.frames, "Show N display frames, save --screenshot, exit")->check(CLI::PositiveNumber);
  preview->add_option("--screenshot", pv.screenshot, "PNG of what the window shows (with --frames)");
  preview->add_option("--device", pv.device, "Vulkan device index")->check(CLI::NonNegativeNumber);
  preview->add_option("--width", pv.width, "Window width (overrides film.width)")->check(CLI::Range(16, pyrolume::kMaxFilmSide));
  preview->add_option("--height", pv.height, "Window height (overrides film.height)")->check(CLI::Range(16, pyrolume::kMaxFilmSide));
  preview->add_option("--exposure", pv.exposure, "Starting exposure in stops (within ±30), or auto (overrides film.exposure)")
      ->check(kExposure);
  preview->add_option("--view", pv.view,
                      "Starting view transform, agx | agx_punchy | filmic | standard (overrides film.view; V cycles)")
      ->check(kView);
  return preview;
}

// `pyrolume denoise`: its options fill `dn`.
CLI::App* add_denoise_command(CLI::App& app, pyrolume::DenoiseArgs& dn) {
  using namespace pyrolume;
  CLI::App* denoise = app.add_subcommand("denoise", "Denoise a render (EXR with variance) into a new image");
  denoise->add_option("input", dn.input, "EXR written by render --variance (read only)")->required();
  denoise->add_option("-o,--output", dn.output, "Output image (.exr, or .png)")->required();
  denoise->add_flag("--no-guide", dn.no_guide,
                    "Use the plain à-trous filter even where the input has the AOVs and their guide (render --aovs), "
                    "which otherwise choose the guided filter; implied by the three options below");
  denoise->add_option("--iterations", dn.iterations,
                      "Plain filter: à-trous iterations (default 1; n reach ±(2^(n+1) − 2) px)")
      ->check(CLI::Range(0, 12));
  // The edge-stopping widths divide differences: NaN, an infinity or 0 would
  // write NaN (or nothing filtered) into the image; the filter holds them as floats.
  const CLI::Validator finite_positive =
      positive_finite("standard deviations (single precision)", double(std::numeric_limits<float>::max()));
  denoise->add_option("--sigma-l", dn.sigma_l,
                      "Plain filter: luminance edge-stopping, in standard deviations of the noise (default 1.5)")
      ->check(finite_positive);
  denoise->add_flag("--features", dn.features,
                    "Plain filter: also stop at edges in the albedo, normal and depth AOVs (off: they measured worse "
                    "on the fires)");
  denoise->add_option("--device", dn.device, "Vulkan device index")->check(CLI::NonNegativeNumber);
  return denoise;
}

}  // namespace

int main(int argc, char** argv) {
  // One malloc arena: llvmpipe runs each dispatch on worker threads, and
  // glibc's default of one arena per thread let freed memory pile up in
  // them. terrain_explosion at 64x36, 2048 spp peaked at 1.8 GB of RSS with
  // the default and at 0.65 GB with one arena; a 320x180 4096-spp render had
  // been killed for memory on a 23 GB machine (docs/robustness.md).
  mallopt(M_ARENA_MAX, 1);
  using namespace pyrolume;
  CLI::App app{"pyrolume: a renderer for fire, smoke and explosions (emissive participating media)"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "pyrolume 0.1.0");

  RenderArgs render_args;
  CLI::App* render = add_render_command(app, render_args);

  PreviewArgs pv;
  CLI::App* preview = add_preview_command(app, pv);

  std::string info_file;
  bool info_values = false;
  auto* info = app.add_subcommand("info", "Print a VDB/NanoVDB file's grids: types, transforms, bboxes, counts, ranges");
  info->add_option("file", info_file, "A .vdb or .nvdb file")->required();
  info->add_flag("--values", info_values, "Read every voxel for exact counts and ranges (slower)");

  int devices_device = -1;
  auto* devices = app.add_subcommand("devices", "List the Vulkan devices and which one is chosen");
  devices->add_option("--device", devices_device, "Device index to mark as chosen")->check(CLI::NonNegativeNumber);

  BlackbodyArgs bb;
  auto* blackbody = app.add_subcommand("blackbody", "Print blackbody colours as CSV: kelvin,x,y,r,g,b");
  blackbody->add_option("--from", bb.from_k, "First temperature, K")->required();
  blackbody->add_option("--to", bb.to_k, "Last temperature, K (inclusive)")->required();
  blackbody->add_option("--step", bb.step_k, "Step, K")->required();
  blackbody->add_option("--mode", bb.mode, "chromaticity (default; also: seed) | stefan_boltzmann | physical | peak")
      ->check(CLI::IsMember({"chromaticity", "seed", "stefan_boltzmann", "peak", "physical"}));
  blackbody->add_option("--observer", bb.observer, "2 (CIE 1931) or 10 (CIE 1964)")->check(CLI::IsMember({2, 10}));
  blackbody->add_option("--png", bb.png, "Also draw the swatch strip to this PNG");

  CompareArgs cmp;
  auto* compare = app.add_subcommand("compare", "Compare image A against reference B: RMSE, relMSE, bias");
  compare->add_option("a", cmp.a, "Test image")->required();
  compare->add_option("b", cmp.b, "Reference image")->required();
  compare->add_option("--max-relmse", cmp.max_relmse, "Exit 3 if relMSE exceeds X");
  compare->add_option("--max-outliers", cmp.max_outliers, "Exit 3 if the fraction beyond 4 sigma exceeds F");

  DenoiseArgs dn;
  CLI::App* denoise = add_denoise_command(app, dn);

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    const bool unknown_word = dynamic_cast<const CLI::ExtrasError*>(&e) || dynamic_cast<const CLI::RequiredError*>(&e);
    std::cerr << "pyrolume: " << e.what() << (unknown_word ? flag_suggestion(app, argc, argv) : "") << " (see --help)\n";
    return 2;
  }

  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);

  try {
    if (*render) {
      int status = run_render(render_args, g_cancel);
      if (g_signal == SIGINT) return 130;
      if (g_signal == SIGTERM) return 143;
      return status;
    }
    if (*preview) return run_preview_command(pv);
    if (*info) return run_info(info_file, info_values);
    if (*devices) return run_devices(devices_device);
    if (*blackbody) return run_blackbody(bb);
    if (*compare) return run_compare(cmp);
    if (*denoise) {
      // The plain filter's settings ask for the plain filter.
      dn.no_guide = dn.no_guide || denoise->count("--iterations") + denoise->count("--sigma-l") + denoise->count("--features") > 0;
      const int status = run_denoise(dn, g_cancel);
      if (g_signal == SIGINT) return 130;
      if (g_signal == SIGTERM) return 143;
      return status;
    }
  } catch (const InputError& e) {
    std::cerr << "pyrolume: " << e.what() << "\n";
    return 2;
  } catch (const NoDeviceError& e) {
    std::cerr << "pyrolume: " << e.what() << "\n";
    return 2;
  } catch (const std::bad_alloc&) {
    // Last resort: inputs are sized against the memory available before they
    // are allocated (docs/robustness.md "Limits"); this is what slipped past.
    std::cerr << "pyrolume: out of memory: an allocation failed (std::bad_alloc); nothing more was written\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "pyrolume: internal error: " << e.what() << "\n";
    return 1;
  }
  return 1;
}
