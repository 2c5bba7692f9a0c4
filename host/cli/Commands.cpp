#include "cli/Commands.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "color/Blackbody.h"
#include "image/AtomicFile.h"
#include "image/Compare.h"
#include "image/ImageIo.h"
#include "image/RenderImage.h"
#include "render/Backend.h"
#include "render/vulkan/Devices.h"
#include "scene/Scene.h"
#include "util/Error.h"
#include "util/Progress.h"
#include "util/ResourceUsage.h"
#include "volume/VdbInfo.h"

namespace pyrolume {
namespace {

std::string lower_extension(const std::filesystem::path& p) {
  std::string e = p.extension().string();
  for (auto& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

std::string format_seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", s);
  return buf;
}

}  // namespace

int run_render(const RenderArgs& args, const std::atomic<bool>& cancel) {
  Scene scene = load_scene(args.scene);

  std::filesystem::path output = args.output.empty()
                                     ? std::filesystem::path(std::filesystem::path(args.scene).stem().string() + ".exr")
                                     : std::filesystem::path(args.output);
  std::string ext = lower_extension(output);
  if (ext != ".exr" && ext != ".png")
    throw input_error(output.string(), "", "unknown image type \"" + ext + "\" (use .exr or .png)");
  if (args.variance && ext != ".exr") throw input_error(output.string(), "", "--variance needs an .exr output");
  if (output.has_parent_path() && !std::filesystem::is_directory(output.parent_path()))
    throw input_error(output.string(), "", "output folder does not exist");
  if (!args.stats.empty()) {
    std::filesystem::path sp(args.stats);
    if (sp.has_parent_path() && !std::filesystem::is_directory(sp.parent_path()))
      throw input_error(args.stats, "", "stats folder does not exist");
  }

  // Accepted by the v1 format but not rendered yet: say so rather than ignore silently.
  if (!scene.shapes.empty() && scene.integrator.mis)
    std::cerr << "pyrolume: warning: " << scene.file.string()
              << ": integrator.mis: light sampling is not implemented yet; surfaces are lit by BSDF sampling only\n";

  RenderSettings settings;
  settings.width = args.width.value_or(scene.film.width);
  settings.height = args.height.value_or(scene.film.height);
  settings.spp = args.spp.value_or(scene.film.spp);
  settings.seed = args.seed.value_or(scene.film.seed);
  settings.time_limit = args.time_limit;

  BackendOptions options;
  options.device_index = args.device;
  auto backend = make_backend(args.backend, options);

  ProgressBar bar("rendering");
  RenderControl control;
  control.progress = [&](int done, int target) { bar.update(done, target); };
  control.cancel = &cancel;
  RenderResult result = backend->render(scene, settings, control);
  bar.finish();

  Image image = image_from_render(result, args.variance);
  write_image(output, image, scene.film.exposure);

  const double samples = double(result.width) * result.height * result.spp;
  if (!args.stats.empty()) {
    nlohmann::ordered_json j;
    j["backend"] = result.backend;
    j["device"] = result.device;
    j["scene"] = args.scene;
    j["output"] = output.string();
    j["width"] = result.width;
    j["height"] = result.height;
    j["spp"] = result.spp;
    j["seconds"] = result.seconds;
    j["load_seconds"] = result.load_seconds;
    j["samples_per_second"] = result.seconds > 0 ? samples / result.seconds : 0.0;
    j["peak_rss_mb"] = peak_rss_mb();
    j["density_lookups_per_ray"] = samples > 0 ? result.density_lookups / samples : 0.0;
    j["lookups_per_second"] = result.seconds > 0 ? result.density_lookups / result.seconds : 0.0;
    j["events_per_path"] = samples > 0 ? result.events / samples : 0.0;
    j["nonfinite_samples"] = result.nonfinite_samples;
    j["cancelled"] = result.cancelled;
    write_text_atomic(args.stats, j.dump(2) + "\n");
  }
  for (const auto& w : result.warnings) std::cerr << "pyrolume: warning: " << w << "\n";
  if (result.nonfinite_samples > 0)
    std::cerr << "pyrolume: warning: " << result.nonfinite_samples << " non-finite samples were recorded as 0\n";
  if (result.cancelled) std::cerr << "pyrolume: interrupted after " << result.spp << " spp; the image so far is saved\n";

  char line[512];
  std::snprintf(line, sizeof line, "%s: %dx%d, %d spp, %s s, %.2f Msamples/s, %s (%s)", output.string().c_str(),
                result.width, result.height, result.spp, format_seconds(result.seconds).c_str(),
                result.seconds > 0 ? samples / result.seconds * 1e-6 : 0.0, result.device.c_str(),
                result.backend.c_str());
  std::cout << line << std::endl;
  return 0;
}

int run_devices(int device) {
  auto list = vk::list_devices();
  int chosen = vk::choose_device(list, device);
  std::cout << vk::format_device_list(list, chosen);
  return 0;
}

int run_info(const std::string& file, bool values) { return run_info_command(file, values, std::cout); }

int run_blackbody(const BlackbodyArgs& a) {
  BlackbodyMode mode = a.mode == "peak" ? BlackbodyMode::Peak : a.mode == "physical" ? BlackbodyMode::Physical : BlackbodyMode::Seed;
  return color::run_blackbody_command(a.from_k, a.to_k, a.step_k, mode, a.observer, a.png, std::cout, std::cerr);
}

int run_compare(const CompareArgs& a) {
  return run_compare_command(a.a, a.b, a.max_relmse, a.max_outliers, std::cout, std::cerr);
}

}  // namespace pyrolume
