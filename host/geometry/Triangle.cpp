#include "geometry/Triangle.h"

#include <bit>
#include <cmath>
#include <cstdint>

namespace pyrolume::geometry {

glm::dvec3 offset_ray_origin(const glm::dvec3& p, const glm::dvec3& n) {
  // Ray Tracing Gems ch. 6: move by a few float ulps (integer steps on the bit
  // pattern) far from the origin, by a fixed epsilon near it, where ulps shrink
  // to nothing. Done on the float position, as the GPU does.
  constexpr float kOrigin = 1.0f / 32.0f, kFloatScale = 1.0f / 65536.0f, kIntScale = 256.0f;
  glm::dvec3 out;
  for (int i = 0; i < 3; ++i) {
    const float pi = float(p[i]), ni = float(n[i]);
    const int32_t of = int32_t(kIntScale * ni);
    const float stepped = std::bit_cast<float>(std::bit_cast<int32_t>(pi) + (pi < 0.0f ? -of : of));
    out[i] = std::fabs(pi) < kOrigin ? double(pi + kFloatScale * ni) : double(stepped);
  }
  return out;
}

std::vector<Triangle> triangles_of(const Mesh& mesh, uint32_t material, uint32_t mesh_index, uint32_t first_source) {
  std::vector<Triangle> out;
  out.reserve(mesh.triangles.size());
  for (size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& c = mesh.triangles[i];
    Triangle t;
    t.material = material;
    t.mesh = mesh_index;
    t.source = first_source + uint32_t(i);
    t.has_normals = c[0].normal != kNoIndex;
    t.has_uvs = c[0].uv != kNoIndex;
    for (int k = 0; k < 3; ++k) {
      t.p[k] = mesh.positions[c[k].position];
      if (t.has_normals) t.n[k] = mesh.normals[c[k].normal];
      if (t.has_uvs) t.uv[k] = mesh.uvs[c[k].uv];
    }
    out.push_back(t);
  }
  return out;
}

TriangleRay::TriangleRay(const Ray& ray) : origin(ray.origin) {
  const glm::dvec3& d = ray.direction;
  const glm::dvec3 a = glm::abs(d);
  kz = (a.x > a.y) ? (a.x > a.z ? 0 : 2) : (a.y > a.z ? 1 : 2);
  kx = (kz + 1) % 3;
  ky = (kx + 1) % 3;
  // Swapping keeps the winding (only matters for one-sided tests; kept so the
  // barycentrics match the paper's).
  if (d[kz] < 0.0) std::swap(kx, ky);
  Sx = d[kx] / d[kz];
  Sy = d[ky] / d[kz];
  Sz = 1.0 / d[kz];
}

bool intersect_triangle(const TriangleRay& r, const Triangle& tri, double t_max, double& t, double& b1, double& b2) {
  // Woop et al. 2013, section 3: translate to the ray origin, shear so the ray
  // runs along +z, then 2D edge functions whose signs decide the hit exactly
  // as long as they are computed consistently for a shared edge.
  const glm::dvec3 A = glm::dvec3(tri.p[0]) - r.origin;
  const glm::dvec3 B = glm::dvec3(tri.p[1]) - r.origin;
  const glm::dvec3 C = glm::dvec3(tri.p[2]) - r.origin;
  const double Ax = A[r.kx] - r.Sx * A[r.kz], Ay = A[r.ky] - r.Sy * A[r.kz];
  const double Bx = B[r.kx] - r.Sx * B[r.kz], By = B[r.ky] - r.Sy * B[r.kz];
  const double Cx = C[r.kx] - r.Sx * C[r.kz], Cy = C[r.ky] - r.Sy * C[r.kz];
  const double U = Cx * By - Cy * Bx;
  const double V = Ax * Cy - Ay * Cx;
  const double W = Bx * Ay - By * Ax;
  // Two-sided: all three edge functions must share a sign (zero counts as both).
  if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return false;
  double det = U + V + W;
  if (det == 0.0) return false;  // the ray lies in the triangle's plane
  const double Az = r.Sz * A[r.kz], Bz = r.Sz * B[r.kz], Cz = r.Sz * C[r.kz];
  double T = U * Az + V * Bz + W * Cz;
  // Compare T/det with (0, t_max) without dividing: flip both to det > 0.
  const double sign = det < 0.0 ? -1.0 : 1.0;
  const double Ts = T * sign, dets = det * sign;
  if (Ts <= 0.0 || Ts >= t_max * dets) return false;
  const double inv = 1.0 / det;
  t = T * inv;
  b1 = V * inv;
  b2 = W * inv;
  return true;
}

void finish_triangle_hit(const Triangle& tri, const Ray& ray, SurfaceHit& hit) {
  const double b0 = 1.0 - hit.b1 - hit.b2;
  hit.kind = HitKind::Triangle;
  hit.position = ray.origin + hit.t * ray.direction;
  const glm::dvec3 p0(tri.p[0]), p1(tri.p[1]), p2(tri.p[2]);
  glm::dvec3 ng = glm::cross(p1 - p0, p2 - p0);
  const double len = glm::length(ng);
  hit.normal = len > 0.0 ? ng / len : glm::dvec3(0.0, 1.0, 0.0);
  hit.shading_normal = hit.normal;
  if (tri.has_normals) {
    glm::dvec3 ns = b0 * glm::dvec3(tri.n[0]) + hit.b1 * glm::dvec3(tri.n[1]) + hit.b2 * glm::dvec3(tri.n[2]);
    const double ls = glm::length(ns);
    if (ls > 0.0) hit.shading_normal = ns / ls;
  }
  hit.uv = tri.has_uvs ? b0 * glm::dvec2(tri.uv[0]) + hit.b1 * glm::dvec2(tri.uv[1]) + hit.b2 * glm::dvec2(tri.uv[2])
                       : glm::dvec2(0.0);
  hit.material = tri.material;
}

}  // namespace pyrolume::geometry
