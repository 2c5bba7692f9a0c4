#pragma once
// `pyrolume preview`: a GLFW window with a Vulkan swapchain that shows the
// progressive render as it converges (issue 7).
#include <optional>
#include <string>

namespace pyrolume {

struct PreviewArgs {
  std::string scene;
  int frames = 0;          // > 0: show this many display frames, then save --screenshot and exit
  std::string screenshot;  // PNG written from what the window shows
  int device = -1;
  std::optional<int> width, height;
  std::string exposure;  // stops or "auto", overriding film.exposure; empty = the scene's
  std::string view;      // one of film.view's names, overriding film.view; empty = the scene's
};

// Returns the exit status. Without a display, without GLFW at build time, or
// without surface support: one line on stderr suggesting `render`, status 2.
int run_preview_command(const PreviewArgs& args);

// True when this build has the preview (GLFW found at configure time).
bool preview_available();

}  // namespace pyrolume
