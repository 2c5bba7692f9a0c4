#include "cli/Commands.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "backends/Backends.h"
#include "cli/OutputCheck.h"
#include "cli/RenderOutput.h"
#include "cli/Sequence.h"
#include "color/Blackbody.h"
#include "denoise/Denoise.h"
#include "image/AtomicFile.h"
#include "image/Compare.h"
#include "image/DisplayTransform.h"
#include "image/ImageIo.h"
#include "render/Checkpoint.h"
#include "render/RenderImage.h"
#include "render/SceneSetup.h"
#include "scene/Scene.h"
#include "util/Error.h"
#include "util/Progress.h"
#include "util/ResourceUsage.h"
#include "volume/VdbInfo.h"

namespace pyrolume {
namespace {

using namespace cli_output;

// A render's control for the command line: each pass prints the scene's
// remarks above `bar`, then moves it; `cancel` (SIGINT/SIGTERM) stops the
// render between passes.
RenderControl bar_control(ProgressBar& bar, SceneRemarks& remarks, const std::atomic<bool>& cancel) {
  RenderControl control;
  control.progress = [&bar, &remarks](int done, int target) {
    remarks.say(&bar);
    bar.update(done, target);
  };
  control.cancel = &cancel;
  return control;
}

int run_sequence(const RenderArgs& args, const Scene& scene, const std::filesystem::path& output,
                 const std::atomic<bool>& cancel, SceneRemarks& remarks, std::optional<int> key_frame) {
  if (args.checkpoint > 0.0 || args.resume)
    throw input_error(args.checkpoint > 0.0 ? "--checkpoint" : "--resume", "",
                      "is for single renders; a sequence resumes by frames with --skip-existing");
  const FrameRange range = parse_frame_range(args.frames);
  if (!has_frame_pattern(output.string()))
    throw input_error(output.string(), "",
                      "with --frames the output must be a frame pattern (#### or $F4), e.g. out_####.exr");
  if (!args.stats.empty() && !has_frame_pattern(args.stats))
    throw input_error(args.stats, "", "with --frames --stats must be a frame pattern too, e.g. stats_####.json");
  // The first frame's outputs before the backend starts; each frame's again before its render.
  CreatedFolders folders;
  auto frame_outputs = [&](int frame) {
    const std::filesystem::path image = expand_frame_pattern(output.string(), frame);
    return FrameOutputs{image,
                        args.stats.empty() ? std::filesystem::path()
                                           : std::filesystem::path(expand_frame_pattern(args.stats, frame)),
                        args.denoise ? denoised_path(image) : std::filesystem::path()};
  };
  check_frame_outputs(frame_outputs(range.first), scene_at_frame(scene, range.first), folders);
  // --denoise: the denoiser's limits come from the film size (the same for
  // every frame), so a film it cannot take is refused before any frame is spent.
  DenoiserSession denoiser;  // one device for the whole sequence
  if (args.denoise) {
    const RenderSettings first = settings_from(args, scene_at_frame(scene, range.first));
    denoiser.check_size(first.width, first.height, args.device, frame_outputs(range.first).denoised.string());
  }

  const auto t0 = std::chrono::steady_clock::now();
  BackendOptions options;
  options.device_index = args.device;
  options.frame_reuse = true;
  auto backend = make_backend(args.backend, options);

  // Auto exposure comes from the shot's key frame (a scene with frame
  // patterns: docs/render-farm.md), else from the first frame rendered, and
  // holds for the rest (no flicker).
  DisplayExposure exposure(parse_exposure(args.exposure));
  const std::string ext = lower_extension(output);
  std::optional<RenderResult> key_render;  // the key frame's, when the loop renders it too
  if (key_frame && ext == ".png") {
    const Scene key_scene = scene_at_frame(scene, *key_frame);
    if (exposure.automatic(key_scene.film) && missing_inputs(scene, key_scene).empty()) {
      RenderSettings settings = settings_from(args, key_scene);
      settings.frame = uint32_t(*key_frame);
      ProgressBar bar("key frame " + std::to_string(*key_frame) + " (auto exposure)");
      RenderControl control = bar_control(bar, remarks, cancel);
      RenderResult result = backend->render(key_scene, settings, control);
      remarks.say(&bar);
      bar.finish();
      if (result.cancelled) {
        std::cerr << "pyrolume: interrupted in the key frame " << *key_frame << "; no frame is written\n";
        return 0;
      }
      std::cerr << "pyrolume: the shot's auto exposure comes from its key frame " << *key_frame << "\n";
      exposure.stops(key_scene.film, image_from_render(result, false), display_log(output));
      const bool in_range = *key_frame >= range.first && *key_frame <= range.last &&
                            (*key_frame - range.first) % range.step == 0;
      if (in_range) key_render = std::move(result);
    }
  }
  bool look_warned = false;
  int rendered = 0, skipped = 0, missing = 0, not_denoised = 0, denoise_status = 0;
  double load_seconds = 0.0, render_seconds = 0.0;
  for (int frame : range) {
    if (cancel.load()) break;
    const std::string tag = "frame " + std::to_string(frame) + ": ";
    const FrameOutputs out = frame_outputs(frame);
    // Outputs are written atomically (temp + rename), so an existing one is
    // complete. With --denoise a frame is done when its denoised copy exists
    // too: one whose denoiser failed is rendered again.
    std::error_code ec;
    if (args.skip_existing && std::filesystem::exists(out.image, ec) &&
        (out.denoised.empty() || std::filesystem::exists(out.denoised, ec))) {
      std::cerr << "pyrolume: " << tag << out.image.string() << " exists, skipped\n";
      ++skipped;
      continue;
    }
    Scene frame_scene = scene_at_frame(scene, frame);
    std::vector<std::string> absent = missing_inputs(scene, frame_scene);
    if (!absent.empty()) {
      for (const auto& a : absent) std::cerr << "pyrolume: " << tag << "missing input " << a << "\n";
      if (missing == 0) print_how_to_make_inputs(scene, frame_scene);
      if (args.strict) {
        std::cerr << "pyrolume: stopping at the missing frame " << frame << " (--strict)\n";
        return 2;
      }
      ++missing;
      continue;
    }

    check_frame_outputs(out, frame_scene, folders);

    RenderSettings settings = settings_from(args, frame_scene);
    settings.frame = uint32_t(frame);
    ProgressBar bar("frame " + std::to_string(frame));
    bar.status("loading its volumes, lights and shaders ...");
    RenderControl control = bar_control(bar, remarks, cancel);
    RenderResult result;
    if (key_render && frame == *key_frame) {
      result = std::move(*key_render);  // rendered above for the exposure, with these settings
      key_render.reset();
    } else {
      result = backend->render(frame_scene, settings, control);
    }
    remarks.say(&bar);
    bar.finish();
    if (result.cancelled) {
      // A partly converged frame is not complete: write nothing, so that
      // --skip-existing renders it again.
      std::cerr << "pyrolume: interrupted in frame " << frame << " after " << result.spp
                << " spp; that frame is not written (rerun with --skip-existing to resume)\n";
      break;
    }
    Image full = image_from_render(result, args.variance || args.denoise);
    full.transparent = frame_scene.film.transparent;
    const Image image = requested_image(full, args, frame_scene);
    const double stops = exposure.stops(frame_scene.film, image, display_log(out.image));
    {
      OutputCommit both;  // the image and its stats, or neither
      write_image(out.image, image, stops, frame_scene.film.view);
      if (!out.stats.empty()) write_stats(out.stats, args, out.image, result, frame);
      both.commit();
    }
    // The denoised copy after the frame is safe: its failure loses only the copy.
    if (!out.denoised.empty())
      if (const int status = write_denoised_copy(out.denoised, out.image, full, stops, frame_scene.film.view, denoiser,
                                                 tag, false);
          status != 0) {
        ++not_denoised;
        denoise_status = std::max(denoise_status, status);
      }
    print_warnings(result, tag);
    if (!look_warned)  // once per sequence, at the first frame it concerns
      if (const std::string w = film_look_warning(image, stops, frame_scene.film.view, ext == ".png", film_cause(frame_scene));
          !w.empty()) {
        std::cerr << "pyrolume: warning: " << tag << w << "\n";
        look_warned = true;
      }
    print_summary(out.image, result);
    ++rendered;
    load_seconds += result.load_seconds;
    render_seconds += result.seconds;
  }
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  char line[512];
  std::snprintf(line, sizeof line,
                "frames %s: %d rendered, %d skipped, %d missing; %s s (%s s loading, %s s rendering)",
                args.frames.c_str(), rendered, skipped, missing, format_seconds(wall).c_str(),
                format_seconds(load_seconds).c_str(), format_seconds(render_seconds).c_str());
  std::cout << line << std::endl;
  if (not_denoised > 0)
    std::cerr << "pyrolume: " << not_denoised << (not_denoised == 1 ? " frame has" : " frames have")
              << " no denoised copy (the raw frames are kept; --skip-existing renders them again): exit status "
              << denoise_status << "\n";
  if (missing > 0 && !args.allow_missing) {
    std::cerr << "pyrolume: " << missing << (missing == 1 ? " frame was" : " frames were")
              << " not rendered for missing inputs: exit status 2 (--allow-missing accepts them)\n";
    return std::max(2, denoise_status);
  }
  return denoise_status;
}

}  // namespace

int run_render(const RenderArgs& args, const std::atomic<bool>& cancel) {
  parse_exposure(args.exposure);  // a bad --exposure or --view fails before the scene loads
  const std::optional<ViewTransform> view = parse_view(args.view);
  Scene scene = load_scene(args.scene);
  if (view) scene.film.view = *view;

  const bool sequence = !args.frames.empty();
  // Source conventions, up axis and framing; a frame pattern's from its whole
  // shot, never from the frames asked for.
  const SceneSetup setup = complete_scene(scene, args.width || args.height || scene.film.size_given);
  const double aspect =
      double(args.width.value_or(scene.film.width)) / double(args.height.value_or(scene.film.height));
  // Said once the render is under way (every input check passed), so that a
  // refused command prints its one error line and nothing else.
  SceneRemarks remarks;
  for (const std::string& note : setup.notes) remarks.lines.push_back("pyrolume: note: " + note);
  if (const std::string w = nothing_emits(scene); !w.empty())
    remarks.lines.push_back("pyrolume: warning: " + scene.file.string() + ": " + w);
  if (!scene.camera.framed_automatically)
    if (const std::string w = nothing_in_view(scene.camera, setup.boxes, aspect); !w.empty())
      remarks.lines.push_back("pyrolume: warning: " + scene.file.string() + ": " + w);
  std::filesystem::path output =
      !args.output.empty() ? std::filesystem::path(args.output)
      : sequence           ? std::filesystem::path(std::filesystem::path(args.scene).stem().string() + "_####.exr")
                           : std::filesystem::path(std::filesystem::path(args.scene).stem().string() + ".exr");
  std::string ext = lower_extension(output);
  if (ext != ".exr" && ext != ".png")
    throw input_error(output.string(), "", "unknown image type \"" + ext + "\" (use .exr or .png)");
  if (args.variance && ext != ".exr") throw input_error(output.string(), "", "--variance needs an .exr output");
  if (args.aovs && ext != ".exr") throw input_error(output.string(), "", "--aovs needs an .exr output (PNG has no layers)");
  if (scene.film.aovs && ext != ".exr")
    throw input_error(scene.file.string(), "film.aovs", "needs an .exr output (PNG has no layers), not " + output.string());
  // Checkpoints carry the beauty and alpha, not the AOVs (docs/checkpoints.md).
  if (render_aovs(args, scene)) {
    const std::string no_aovs =
        "checkpoints do not carry AOVs (" + (args.aovs ? std::string("--aovs") : scene.file.string() + ": film.aovs") + ")";
    if (args.resume) throw input_error("--resume", "", no_aovs + ": render again without --resume");
    if (args.checkpoint > 0.0) throw input_error("--checkpoint", "", no_aovs);
  }

  if (sequence) return run_sequence(args, scene, output, cancel, remarks, setup.key_frame);

  if (args.skip_existing) throw input_error("--skip-existing", "", "needs --frames");
  if (args.strict) throw input_error("--strict", "", "needs --frames");
  if (args.allow_missing) throw input_error("--allow-missing", "", "needs --frames");
  if (has_frame_pattern(output.string()))
    throw input_error(output.string(), "", "the output is a frame pattern: give --frames A-B (or one frame, --frames N)");
  for (size_t i = 0; i < scene.media.size(); ++i)
    if (scene.media[i].type == Medium::Type::Vdb && has_frame_pattern(scene.media[i].file.string()))
      throw input_error(scene.file.string(), "media[" + std::to_string(i) + "].file",
                        "is a frame pattern: give --frames A-B (or one frame, --frames N)");
  // Every output checked (and its folder made) before anything renders: none
  // may be an input or another output, and each must be writable.
  const std::filesystem::path checkpoint_file = checkpoint_path(output);
  CreatedFolders folders;
  {
    std::vector<NamedPath> outputs{{"-o", output}};
    if (!args.stats.empty()) outputs.push_back({"--stats", args.stats});
    if (args.denoise) outputs.push_back({"--denoise", denoised_path(output)});
    check_outputs(outputs, {{"the checkpoint (-o + .checkpoint)", checkpoint_file}}, scene_inputs(scene), folders);
  }

  // Without --frames the render is frame 0: keys evaluate there (clamped) and
  // the RNG is keyed with frame 0, as before animation existed.
  RenderSettings settings = settings_from(args, scene);
  settings.frame = 0;
  // --denoise: a film too large for the denoiser is refused before the render is spent.
  DenoiserSession denoiser;
  if (args.denoise) denoiser.check_size(settings.width, settings.height, args.device, denoised_path(output).string());

  // Checkpoints: OUT.checkpoint (checkpoint_file) carries the accumulation and what it belongs to.
  CheckpointIdentity identity{args.backend, args.scene,     scene_fingerprint(args.scene), settings.width,
                              settings.height, settings.seed, settings.frame,                 ""};
  std::optional<Checkpoint> resumed;
  if (args.resume) {
    std::error_code ec;
    if (std::filesystem::exists(checkpoint_file, ec)) {
      resumed = read_checkpoint(checkpoint_file);
      check_resumable(checkpoint_file, *resumed, identity, settings.spp);
    } else {
      std::cerr << "pyrolume: warning: --resume: there is no " << checkpoint_file.string()
                << "; rendering from 0 spp\n";
    }
  }

  BackendOptions options;
  options.device_index = args.device;
  auto backend = make_backend(args.backend, options);
  identity.device = backend->device_name();

  // A checkpoint that cannot be written must not end the render: warn once.
  bool checkpoint_warned = false;
  auto save_checkpoint = [&](const AccumulationState& state) {
    try {
      write_checkpoint(checkpoint_file, identity, settings.spp, state);
      return true;
    } catch (const InputError& e) {
      if (!checkpoint_warned) std::cerr << "pyrolume: warning: checkpoint not saved: " << e.what() << "\n";
      checkpoint_warned = true;
      return false;
    }
  };

  ProgressBar bar("rendering");
  bar.status("loading the scene's volumes, lights and shaders ...");
  RenderControl control = bar_control(bar, remarks, cancel);
  if (resumed) control.resume = &resumed->state;
  if (args.checkpoint > 0.0) {
    control.checkpoint_seconds = args.checkpoint;
    control.checkpoint = [&](const AccumulationState& state) { save_checkpoint(state); };
  }

  // The image and (short of the target) the checkpoint of what was rendered.
  DisplayExposure exposure(parse_exposure(args.exposure));
  int denoise_status = 0;  // a failed denoised copy: the exit status at the end
  auto save = [&](const RenderResult& result, bool keep_checkpoint) {
    Image full = image_from_render(result, args.variance || args.denoise);
    full.transparent = scene.film.transparent;
    const Image image = requested_image(full, args, scene);
    const double stops = exposure.stops(scene.film, image, display_log(output));
    {
      OutputCommit both;  // the image and the stats, or neither
      write_image(output, image, stops, scene.film.view);
      if (!args.stats.empty()) write_stats(args.stats, args, output, result, std::nullopt);
      both.commit();
    }
    // After the raw image is safe: a failure here loses nothing else (the
    // checkpoint below is still saved).
    if (args.denoise && result.spp > 0)
      denoise_status = write_denoised_copy(denoised_path(output), output, full, stops, scene.film.view, denoiser, "", true);
    if (result.spp >= settings.spp)  // a finished render: one the user will look at
      if (const std::string w = film_look_warning(image, stops, scene.film.view, ext == ".png", film_cause(scene));
          !w.empty())
        std::cerr << "pyrolume: warning: " << output.string() << ": " << w << "\n";
    bool checkpointed = false;
    // The beauty's checkpoint also when --denoise accumulated AOVs for its
    // guide: a resumed render is denoised without them (accumulate_aovs).
    if (result.spp < settings.spp && keep_checkpoint && !render_aovs(args, scene) && !result.state.data.empty())
      checkpointed = save_checkpoint(result.state);
    if (result.spp >= settings.spp) {
      std::error_code ec;
      std::filesystem::remove(checkpoint_file, ec);  // complete: nothing left to resume
    }
    return checkpointed;
  };
  auto resume_hint = [&](bool checkpointed) {
    return checkpointed ? "; continue with --resume (" + checkpoint_file.string() + ")" : std::string();
  };

  RenderResult result;
  try {
    result = backend->render(scene, settings, control);
    remarks.say(&bar);
  } catch (const RenderFailed& e) {
    bar.finish();
    const RenderResult& partial = e.partial;
    if (partial.spp <= 0) {
      std::cerr << "pyrolume: error: " << e.what() << " before any samples were saved; nothing is written\n";
      return 1;
    }
    const bool checkpointed = save(partial, true);
    std::cerr << "pyrolume: error: " << e.what() << "; the image so far (" << partial.spp << " of "
              << settings.spp << " spp) is saved to " << output.string() << resume_hint(checkpointed) << "\n";
    return 1;
  }
  bar.finish();
  if (result.cancelled && result.spp == 0) {  // interrupted within the first pass: no image exists yet
    std::cerr << "pyrolume: interrupted before the first pass finished; nothing is written\n";
    return 0;
  }

  const bool short_of_target = result.spp < settings.spp;
  const bool checkpointed = save(result, result.cancelled || args.checkpoint > 0.0);
  print_warnings(result, "");
  if (result.cancelled)
    std::cerr << "pyrolume: interrupted after " << result.spp << " of " << settings.spp
              << " spp; the image so far is saved to " << output.string() << " (spp " << result.spp << ")"
              << resume_hint(checkpointed) << "\n";
  else if (short_of_target && checkpointed)
    std::cerr << "pyrolume: stopped at " << result.spp << " of " << settings.spp << " spp (--time-limit)"
              << resume_hint(checkpointed) << "\n";
  print_summary(output, result);
  return denoise_status;
}

int run_devices(int device) {
  std::cout << device_list(device);
  return 0;
}

int run_info(const std::string& file, bool values) { return run_info_command(file, values, std::cout); }

int run_blackbody(const BlackbodyArgs& a) {
  const BlackbodyMode mode = color::parse_blackbody_mode(a.mode).value_or(BlackbodyMode::Seed);  // CLI checked the name
  return color::run_blackbody_command(a.from_k, a.to_k, a.step_k, mode, a.observer, a.png, std::cout, std::cerr,
                                      write_file_atomic);
}

int run_compare(const CompareArgs& a) {
  return run_compare_command(a.a, a.b, a.max_relmse, a.max_outliers, std::cout, std::cerr);
}

int run_denoise(const DenoiseArgs& a, const std::atomic<bool>& cancel) {
  const std::filesystem::path input = a.input, output = a.output;
  if (output.empty()) throw input_error(input.string(), "", "no output: give -o OUT.exr");
  const std::string ext = lower_extension(output);
  if (ext != ".exr" && ext != ".png")
    throw input_error(output.string(), "", "unknown image extension '" + output.extension().string() + "' (use .exr or .png)");
  CreatedFolders folders;
  check_outputs({{"-o", output}}, {}, {{"the input", input}}, folders);
  const auto t0 = std::chrono::steady_clock::now();
  const Image noisy = read_image(input);
  // The filter's edge-stopping is in units of the noise: without the variance
  // it would have to guess it, so an image without one is refused.
  if (!noisy.has_variance())
    throw input_error(input.string(), "",
                      "has no variance.R/G/B channels; the denoiser needs them (render with --variance)");
  DenoiseOptions options;
  options.iterations = a.iterations;
  options.sigma_l = a.sigma_l;
  options.use_features = a.features;
  options.use_guide = !a.no_guide;
  options.device_index = a.device;
  // A signal (main.cpp) ends the command with nothing written: checked
  // before the device opens, after the filter, and last before the rename.
  auto interrupted = [&] {
    if (!cancel.load()) return false;
    std::cerr << "pyrolume: interrupted; " << output.string() << " is not written\n";
    return true;
  };
  if (interrupted()) return 0;
  const auto t1 = std::chrono::steady_clock::now();
  const Image clean = denoise(noisy, options, input.string());
  const auto t2 = std::chrono::steady_clock::now();
  if (interrupted()) return 0;
  {
    OutputCommit one;  // destroyed uncommitted, it removes the finished temp file
    write_image(output, clean);
    if (interrupted()) return 0;
    one.commit();
  }
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double filter = std::chrono::duration<double>(t2 - t1).count();
  std::cout << output.string() << ": " << noisy.width << "x" << noisy.height << ", denoised with "
            << denoise_inputs(noisy, options) << ", "
            << format_seconds(filter) << " s denoising, " << format_seconds(total) << " s in all" << std::endl;
  return 0;
}

}  // namespace pyrolume
