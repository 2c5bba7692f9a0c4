#include "color/ChromaticAdaptation.h"
#include "util/Math.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace pyrolume::color {
namespace {

// Bradford cone-response matrix M_B (rows: rho, gamma, beta), Fairchild 1998.
constexpr double kBradford[3][3] = {
    {0.8951, 0.2664, -0.1614},
    {-0.7502, 1.7135, 0.0367},
    {0.0389, -0.0685, 1.0296},
};

// The exact inverse (adjugate / determinant) rather than a rounded published
// table, so that a white maps to exactly the destination white.
struct Inverse {
  double m[3][3];
  Inverse() {
    const auto& a = kBradford;
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        // cofactor of a[c][r]
        const int r0 = (c + 1) % 3, r1 = (c + 2) % 3, c0 = (r + 1) % 3, c1 = (r + 2) % 3;
        m[r][c] = (a[r0][c0] * a[r1][c1] - a[r0][c1] * a[r1][c0]) / det;
      }
  }
};

glm::dvec3 cone_response(const glm::dvec3& white, const char* which) {
  const glm::dvec3 rho = mul(kBradford, white);
  for (int i = 0; i < 3; ++i)
    if (!(rho[i] > 0.0) || !std::isfinite(rho[i]))
      throw std::invalid_argument(std::string("chromatic adaptation: the ") + which +
                                  " white has a non-positive Bradford cone response");
  return rho;
}

}  // namespace

glm::dvec3 von_kries_bradford(const glm::dvec3& xyz, const glm::dvec3& source_white_xyz,
                              const glm::dvec3& dest_white_xyz) {
  static const Inverse inv;
  const glm::dvec3 rho_s = cone_response(source_white_xyz / source_white_xyz.y, "source");
  const glm::dvec3 rho_d = cone_response(dest_white_xyz / dest_white_xyz.y, "destination");
  // Von Kries: scale each cone signal independently by the ratio of the whites.
  const glm::dvec3 lms = mul(kBradford, xyz) * (rho_d / rho_s);
  return mul(inv.m, lms);
}

}  // namespace pyrolume::color
