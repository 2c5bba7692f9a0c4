// Built instead of the real preview when CMake found no GLFW.
#include "preview/Preview.h"

#include <iostream>

namespace pyrolume {
bool preview_available() { return false; }
int run_preview_command(const PreviewArgs& args) {
  std::cerr << "pyrolume: preview: this build has no GLFW (install libglfw3-dev and rebuild); use `pyrolume render "
            << args.scene << " -o out.png` instead\n";
  return 2;
}
}  // namespace pyrolume
