#pragma once
// Turntable camera moves for the preview: orbit, pan and zoom about the scene
// camera's look_at. Header-only and free of GLFW/Vulkan so the tests can check
// the geometry without a window.
#include <algorithm>
#include <cmath>

#include <glm/glm.hpp>

#include "scene/Scene.h"

namespace pyrolume::preview {

// Rodrigues' rotation of v about the unit axis k by angle radians.
inline glm::dvec3 rotate_about(const glm::dvec3& v, const glm::dvec3& k, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return v * c + glm::cross(k, v) * s + k * glm::dot(k, v) * (1.0 - c);
}

// Yaw about the scene's up axis and pitch towards/away from it, keeping the
// distance to look_at. The polar angle stays inside [min_polar, pi - min_polar]
// so the view never flips over the pole (where forward would be parallel to up).
inline void orbit(Camera& cam, double yaw_rad, double pitch_rad, double min_polar = 0.02) {
  const glm::dvec3 up = glm::normalize(cam.up);
  glm::dvec3 offset = cam.position - cam.look_at;
  const double dist = glm::length(offset);
  if (!(dist > 0.0)) return;
  offset = rotate_about(offset, up, yaw_rad);
  const glm::dvec3 side = glm::cross(up, offset);
  const double side_len = glm::length(side);
  if (side_len > 1e-12 * dist) {
    const double polar = std::acos(std::clamp(glm::dot(offset / dist, up), -1.0, 1.0));
    const double target = std::clamp(polar + pitch_rad, min_polar, M_PI - min_polar);
    // Rotating about up × offset by a positive angle moves offset away from up.
    offset = rotate_about(offset, side / side_len, target - polar);
  }
  cam.position = cam.look_at + offset;
}

// Move position and look_at together in the image plane. dx, dy are in pixels
// (y down, as window coordinates are); the scene under the cursor follows it
// at the look_at's depth for a viewport `viewport_height` pixels tall.
inline void pan(Camera& cam, double dx_px, double dy_px, double viewport_height) {
  const glm::dvec3 offset = cam.position - cam.look_at;
  const double dist = glm::length(offset);
  if (!(dist > 0.0) || !(viewport_height > 0.0)) return;
  const glm::dvec3 forward = -offset / dist;
  const glm::dvec3 right = glm::normalize(glm::cross(forward, cam.up));  // image x (docs/scene-format.md "camera")
  const glm::dvec3 image_up = glm::cross(right, forward);
  const double units_per_px = 2.0 * dist * std::tan(glm::radians(cam.fov_deg) * 0.5) / viewport_height;
  const glm::dvec3 move = (-dx_px * right + dy_px * image_up) * units_per_px;
  cam.position += move;
  cam.look_at += move;
}

// Scale the distance to look_at by 0.9 per step (steps > 0 moves closer).
inline void zoom(Camera& cam, double steps) {
  const glm::dvec3 offset = cam.position - cam.look_at;
  const double dist = glm::length(offset);
  if (!(dist > 0.0)) return;
  const double new_dist = std::max(dist * std::pow(0.9, steps), 1e-4);
  cam.position = cam.look_at + offset * (new_dist / dist);
}

}  // namespace pyrolume::preview
