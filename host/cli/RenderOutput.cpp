#include "cli/RenderOutput.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "backends/Backends.h"
#include "cli/OutputCheck.h"
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

namespace pyrolume::cli_output {

std::string format_seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", s);
  return buf;
}

FilmCause film_cause(const Scene& scene) {
  FilmCause c;
  // The pre-render warning (nothing_emits) in short: the cause and its fix.
  if (!nothing_emits(scene).empty())
    c.unlit = scene.lights.empty() ? "nothing in the scene gives light: add lights, background.rgb or an environment"
                                   : "the lights light nothing: set the media's sigma_s (or add a surface)";
  c.emits = false;
  for (const Medium& m : scene.media) c.emits = c.emits || m.emission.emits();
  return c;
}




std::filesystem::path denoised_path(const std::filesystem::path& output) {
  std::filesystem::path p = output;
  p.replace_extension(".denoised" + output.extension().string());
  return p;
}


bool accumulate_aovs(const RenderArgs& args, const Scene& scene) {
  return render_aovs(args, scene) || (args.denoise && args.checkpoint <= 0.0 && !args.resume);
}

Image requested_image(Image image, const RenderArgs& args, const Scene& scene) {
  if (!args.variance) image.variance.clear();
  if (!render_aovs(args, scene)) image.aovs = Aovs{};
  return image;
}

double write_denoised(const std::filesystem::path& file, const Image& image, double stops, ViewTransform view,
                      DenoiserSession& denoiser) {
  const auto t0 = std::chrono::steady_clock::now();
  const Image clean = denoiser.run(image, DenoiseOptions{}, file.string());
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_image(file, clean, stops, view);
  return seconds;
}

int write_denoised_copy(const std::filesystem::path& file, const std::filesystem::path& raw, const Image& image,
                        double stops, ViewTransform view, DenoiserSession& denoiser, const std::string& tag,
                        bool summary) {
  std::string reason;
  int status = 2;
  try {
    OutputCommit one;
    const double seconds = write_denoised(file, image, stops, view, denoiser);
    one.commit();
    if (summary)
      std::cout << file.string() << ": denoised with " << denoise_inputs(image, DenoiseOptions{}) << ", "
                << format_seconds(seconds) << " s" << std::endl;
    return 0;
  } catch (const InputError& e) {
    reason = e.what();
  } catch (const NoDeviceError& e) {
    reason = file.string() + ": " + e.what();
  } catch (const std::bad_alloc&) {
    reason = file.string() + ": out of memory (std::bad_alloc)";
    status = 1;
  } catch (const std::exception& e) {
    reason = file.string() + ": internal error: " + e.what();
    status = 1;
  }
  std::cerr << "pyrolume: error: " << tag << reason << "; the denoised copy is not written, " << raw.string()
            << " is kept\n";
  return status;
}

std::ostream* display_log(const std::filesystem::path& output) {
  return lower_extension(output) == ".png" ? &std::cerr : nullptr;
}

void check_frame_outputs(const FrameOutputs& out, const Scene& frame_scene, CreatedFolders& folders) {
  std::vector<NamedPath> outputs{{"-o", out.image}};
  if (!out.stats.empty()) outputs.push_back({"--stats", out.stats});
  if (!out.denoised.empty()) outputs.push_back({"--denoise", out.denoised});
  check_outputs(outputs, {}, scene_inputs(frame_scene), folders);
}

void write_stats(const std::filesystem::path& file, const RenderArgs& args, const std::filesystem::path& output,
                 const RenderResult& result, std::optional<int> frame) {
  const double samples = double(total_samples(result.width, result.height, result.spp));
  // Rates count this run's samples only (a resumed render's earlier ones took no time here).
  const double new_samples = double(total_samples(result.width, result.height, result.spp - result.resumed_spp));
  nlohmann::ordered_json j;
  j["backend"] = result.backend;
  j["device"] = result.device;
  j["scene"] = args.scene;
  j["light_strategy"] = result.light_strategy;
  j["emission_estimator"] = result.emission_estimator;
  if (!result.majorant_grids.empty()) j["majorant_grids"] = result.majorant_grids;
  j["output"] = output.string();
  if (frame) j["frame"] = *frame;
  j["width"] = result.width;
  j["height"] = result.height;
  j["spp"] = result.spp;
  j["spp_target"] = result.spp_target;
  j["resumed_spp"] = result.resumed_spp;
  j["total_samples"] = total_samples(result.width, result.height, result.spp);
  j["seconds"] = result.seconds;
  j["load_seconds"] = result.load_seconds;
  j["guide_seconds"] = result.guide_seconds;
  j["samples_per_second"] = result.seconds > 0 ? new_samples / result.seconds : 0.0;
  j["peak_rss_mb"] = peak_rss_mb();
  const double lookups_per_ray = samples > 0 ? result.density_lookups / samples : 0.0;
  j["density_lookups_per_ray"] = lookups_per_ray;
  j["lookups_per_second"] = result.seconds > 0 ? lookups_per_ray * new_samples / result.seconds : 0.0;
  j["events_per_path"] = samples > 0 ? result.events / samples : 0.0;
  j["nonfinite_samples"] = result.nonfinite_samples;
  j["dropped_samples"] = result.dropped_samples;
  j["cancelled"] = result.cancelled;
  write_text_atomic(file, j.dump(2) + "\n");
}

void print_summary(const std::filesystem::path& output, const RenderResult& result) {
  const double samples = double(total_samples(result.width, result.height, result.spp - result.resumed_spp));
  char line[512];
  std::snprintf(line, sizeof line, "%s: %dx%d, %d spp, %s s, %.2f Msamples/s, %s (%s)", output.string().c_str(),
                result.width, result.height, result.spp, format_seconds(result.seconds).c_str(),
                result.seconds > 0 ? samples / result.seconds * 1e-6 : 0.0, result.device.c_str(),
                result.backend.c_str());
  std::cout << line << std::endl;
}

void print_warnings(const RenderResult& result, const std::string& prefix) {
  for (const auto& w : result.warnings) std::cerr << "pyrolume: warning: " << prefix << w << "\n";
  if (result.nonfinite_samples > 0)
    std::cerr << "pyrolume: warning: " << prefix << result.nonfinite_samples
              << " non-finite samples were recorded as 0\n";
}

RenderSettings settings_from(const RenderArgs& args, const Scene& scene) {
  RenderSettings settings;
  settings.width = args.width.value_or(scene.film.width);
  settings.height = args.height.value_or(scene.film.height);
  settings.spp = args.spp.value_or(scene.film.spp);
  settings.seed = args.seed.value_or(scene.film.seed);
  settings.time_limit = args.time_limit;
  settings.aovs = accumulate_aovs(args, scene);
  return settings;
}

std::vector<std::string> missing_inputs(const Scene& pattern_scene, const Scene& frame_scene) {
  std::vector<std::string> missing;
  for (size_t i = 0; i < frame_scene.media.size(); ++i) {
    const Medium& m = frame_scene.media[i];
    if (m.type != Medium::Type::Vdb || !has_frame_pattern(pattern_scene.media[i].file.string())) continue;
    std::error_code ec;
    if (!std::filesystem::exists(m.file, ec)) missing.push_back("media[" + std::to_string(i) + "].file: " + m.file.string());
  }
  return missing;
}


void print_how_to_make_inputs(const Scene& pattern_scene, const Scene& frame_scene) {
  for (size_t i = 0; i < frame_scene.media.size(); ++i) {
    const std::filesystem::path folder = frame_scene.media[i].file.parent_path();
    std::error_code ec;
    if (folder.empty() || std::filesystem::is_directory(folder, ec)) continue;
    const std::string pattern = pattern_scene.media[i].file.filename().string();
    if (pattern == "explosion_####.vdb")
      std::cerr << "pyrolume: the folder " << folder.string()
                << " does not exist: tools/gen_explosion_sequence --out " << folder.string()
                << " writes these frames (a build in build/ writes them there)\n";
    else
      std::cerr << "pyrolume: the folder " << folder.string() << " does not exist\n";
    return;
  }
}

// `render --frames`: one backend (one Vulkan device and, through frame reuse,
// one pipeline and BVH) for every frame; each frame is rendered exactly as
// `--frames N-N` would render it alone.

}  // namespace pyrolume::cli_output
