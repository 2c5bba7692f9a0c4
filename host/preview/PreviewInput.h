#pragma once
// The preview window's input (Preview.cpp): what the GLFW callbacks gather
// between two display frames, which the next frame applies (orbit, pan, zoom,
// exposure, view, temperature scale, reset, save; Esc closes the window).
#include <GLFW/glfw3.h>

namespace pyrolume {

// Input gathered by the GLFW callbacks between two frames; the frame applies it.
struct Input {
  double last_x = 0, last_y = 0;
  bool have_last = false;
  double orbit_x = 0, orbit_y = 0;  // pixels dragged with the left button
  double pan_x = 0, pan_y = 0;      // pixels dragged with the right or middle button
  double zoom = 0;                  // wheel steps
  int exposure_steps = 0;
  int view_steps = 0;  // V: the next view transform
  int temperature_steps = 0;
  bool reset = false, save = false;
  bool framebuffer_resized = false;
};

// Points the window's callbacks at `in` (the window's user pointer).
void install_input_callbacks(GLFWwindow* w, Input* in);

}  // namespace pyrolume
