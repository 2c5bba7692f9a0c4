#pragma once
// Random directions for ray tests (the CPU and GPU BVH tests).
#include <random>

#include <glm/glm.hpp>

namespace pyrolume::test {

// A direction uniform on the unit sphere (a normalised Gaussian vector).
inline glm::dvec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  glm::dvec3 d;
  do d = glm::dvec3(n(rng), n(rng), n(rng));
  while (glm::length(d) < 1e-6);
  return glm::normalize(d);
}

}  // namespace pyrolume::test
