#pragma once
// What `render` writes and says around each frame (RenderOutput.cpp), shared
// by a single render and a sequence (Commands.cpp): the outputs' paths, the
// denoised copy, the stats JSON, the summary and warnings, the render
// settings from the command line. Only host/cli includes it.
#include <filesystem>
#include <iostream>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "cli/Commands.h"
#include "cli/OutputCheck.h"
#include "denoise/Denoise.h"
#include "image/DisplayTransform.h"
#include "image/Image.h"
#include "render/Render.h"
#include "render/SceneSetup.h"
#include "scene/Scene.h"
#include "util/Progress.h"

namespace pyrolume::cli_output {

std::string format_seconds(double s);

// What a black image's warning names (film_look_warning).
FilmCause film_cause(const Scene& scene);

// Where one frame goes: the image, and the stats JSON when asked for.
struct FrameOutputs {
  std::filesystem::path image, stats;
  std::filesystem::path denoised;  // render --denoise: OUT.denoised.EXT; else empty
};

// render --denoise: the denoised image goes next to OUT, as OUT.denoised.EXT.
std::filesystem::path denoised_path(const std::filesystem::path& output);

// Whether the user asked for AOVs in the output.
inline bool render_aovs(const RenderArgs& args, const Scene& scene) { return args.aovs || scene.film.aovs; }

// Whether the render accumulates them: when asked for, and for --denoise,
// whose guided filter reads the layers, features and guide (docs/compositing.md
// "Denoiser"), except with checkpoints, which do not carry AOVs: a render
// that keeps or resumes one is denoised from its beauty and variance alone.
bool accumulate_aovs(const RenderArgs& args, const Scene& scene);

// The image as the user asked for it (render --denoise computes variance for
// the denoiser; the raw output keeps only what was asked).
Image requested_image(Image image, const RenderArgs& args, const Scene& scene);

// render --denoise: the denoised image, through the same display transform
// as OUT when it is a PNG. Returns the seconds the filter took (the first
// call also starts the session's device).
double write_denoised(const std::filesystem::path& file, const Image& image, double stops, ViewTransform view,
                      DenoiserSession& denoiser);

// render --denoise: the denoised copy of an image already written, in an
// output commit of its own, so that a failure of the denoiser (or of this
// write) loses nothing but the copy. Returns the exit status the failure asks
// for at the end of the run (2: bad input or no device, 1: anything else), 0
// when the copy is written; a failure is said on one line, naming the raw
// image that was kept. Prints the copy's summary line when `summary`.
int write_denoised_copy(const std::filesystem::path& file, const std::filesystem::path& raw, const Image& image,
                        double stops, ViewTransform view, DenoiserSession& denoiser, const std::string& tag,
                        bool summary);

// Where the auto exposure line goes: stderr, for display output only (an EXR
// is linear; an exposure chosen for it would mean nothing).
std::ostream* display_log(const std::filesystem::path& output);

// One frame's outputs against its inputs, before it is rendered (cli/OutputCheck.h).
void check_frame_outputs(const FrameOutputs& out, const Scene& frame_scene, CreatedFolders& folders);

// The stats JSON of one render (README.md "Using it": --stats).
void write_stats(const std::filesystem::path& file, const RenderArgs& args, const std::filesystem::path& output,
                 const RenderResult& result, std::optional<int> frame);

// "OUT: WxH, N spp, S s, M Msamples/s, DEVICE (BACKEND)" on stdout.
void print_summary(const std::filesystem::path& output, const RenderResult& result);

// Each of the render's warnings on stderr, after prefix.
void print_warnings(const RenderResult& result, const std::string& prefix);

// The renderer's settings from the command line and the scene.
RenderSettings settings_from(const RenderArgs& args, const Scene& scene);

// The media whose file is a frame pattern and whose file for this frame is
// missing: "media[i].file: PATH" each.
std::vector<std::string> missing_inputs(const Scene& pattern_scene, const Scene& frame_scene);

// Notes and warnings about the scene as a whole, held back until the first
// pass is done (or the render returns), then printed once.
struct SceneRemarks {
  std::vector<std::string> lines;
  // The bar's line is cleared first: the remarks go on lines of their own.
  void say(ProgressBar* bar = nullptr) {
    if (bar && !lines.empty()) bar->finish();
    for (const std::string& l : lines) std::cerr << l << "\n";
    lines.clear();
  }
};

// A missing input whose folder does not exist either usually means a
// generated sequence was never generated: say how, for the one pyrolume ships.
void print_how_to_make_inputs(const Scene& pattern_scene, const Scene& frame_scene);

}  // namespace pyrolume::cli_output
