#include "preview/PreviewInput.h"

namespace pyrolume {
namespace {


Input& input_of(GLFWwindow* w) { return *static_cast<Input*>(glfwGetWindowUserPointer(w)); }

void on_cursor(GLFWwindow* w, double x, double y) {
  Input& in = input_of(w);
  if (in.have_last) {
    const double dx = x - in.last_x, dy = y - in.last_y;
    if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS) {
      in.orbit_x += dx;
      in.orbit_y += dy;
    } else if (glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS ||
               glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_MIDDLE) == GLFW_PRESS) {
      in.pan_x += dx;
      in.pan_y += dy;
    }
  }
  in.last_x = x;
  in.last_y = y;
  in.have_last = true;
}

void on_scroll(GLFWwindow* w, double, double dy) { input_of(w).zoom += dy; }

// Characters, not keys: '+', '[' and ']' sit on different keys per layout.
void on_char(GLFWwindow* w, unsigned int c) {
  Input& in = input_of(w);
  switch (c) {
    case '+': case '=': in.exposure_steps++; break;  // '=' is unshifted '+' on US layouts
    case '-': case '_': in.exposure_steps--; break;
    case 'v': case 'V': in.view_steps++; break;
    case ']': in.temperature_steps++; break;
    case '[': in.temperature_steps--; break;
    case 'r': case 'R': in.reset = true; break;
    case 's': case 'S': in.save = true; break;
    default: break;
  }
}

void on_key(GLFWwindow* w, int key, int, int action, int) {
  if (key == GLFW_KEY_ESCAPE && action == GLFW_PRESS) glfwSetWindowShouldClose(w, GLFW_TRUE);
}

void on_framebuffer_size(GLFWwindow* w, int, int) { input_of(w).framebuffer_resized = true; }

}  // namespace

void install_input_callbacks(GLFWwindow* w, Input* in) {
  glfwSetWindowUserPointer(w, in);
  glfwSetCursorPosCallback(w, on_cursor);
  glfwSetScrollCallback(w, on_scroll);
  glfwSetCharCallback(w, on_char);
  glfwSetKeyCallback(w, on_key);
  glfwSetFramebufferSizeCallback(w, on_framebuffer_size);
}

}  // namespace pyrolume
