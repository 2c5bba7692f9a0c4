#include "geometry/SceneSurfaces.h"

#include <cmath>
#include <cstdio>
#include <map>

#include "geometry/Mesh.h"
#include "geometry/Triangle.h"
#include "scene/MediumVolume.h"
#include "util/Error.h"
#include "volume/VdbLoader.h"

namespace pyrolume::geometry {

namespace {

// kMaxCoordinate (scene/Scene.h): surfaces are intersected in float on the GPU.
void check_coordinates(const Scene& scene, const std::string& key, const glm::dvec3& p, const std::string& what) {
  if (std::abs(p.x) <= kMaxCoordinate && std::abs(p.y) <= kMaxCoordinate && std::abs(p.z) <= kMaxCoordinate) return;
  char buf[200];
  std::snprintf(buf, sizeof buf, "%s is at (%.3g, %.3g, %.3g), beyond the +-%.0e that float ray arithmetic keeps finite",
                what.c_str(), p.x, p.y, p.z, kMaxCoordinate);
  throw input_error(scene.file.string(), key, buf);
}

}  // namespace

Surfaces build_surfaces(const Scene& scene) {
  Surfaces out;
  std::map<std::filesystem::path, int> texture_index;
  std::vector<Triangle> triangles;
  for (size_t i = 0; i < scene.shapes.size(); ++i) {
    const Shape& s = scene.shapes[i];
    Material material;
    material.albedo = s.albedo;
    if (!s.texture.empty()) {
      auto it = texture_index.find(s.texture);
      if (it == texture_index.end()) {
        out.textures.push_back(Texture::load(s.texture));
        it = texture_index.emplace(s.texture, int(out.textures.size()) - 1).first;
      }
      material.texture = it->second;
    }
    const uint32_t m = uint32_t(out.materials.size());
    out.materials.push_back(material);
    switch (s.type) {
      case Shape::Type::Mesh: {
        Mesh mesh = load_obj(s.mesh);
        transform_mesh(mesh, medium_transform_matrix(s.transform));  // scale, rotate X/Y/Z, translate
        for (size_t v = 0; v < mesh.positions.size(); ++v)
          check_coordinates(scene, "shapes[" + std::to_string(i) + "].transform", glm::dvec3(mesh.positions[v]),
                            "vertex " + std::to_string(v + 1) + " of " + s.mesh.string() + " (transformed)");
        auto tris = triangles_of(mesh, m, uint32_t(i), uint32_t(triangles.size()));
        triangles.insert(triangles.end(), tris.begin(), tris.end());
        break;
      }
      case Shape::Type::Sphere:
        check_coordinates(scene, "shapes[" + std::to_string(i) + "].sphere", s.center + glm::dvec3(s.radius),
                          "the sphere's extent");
        check_coordinates(scene, "shapes[" + std::to_string(i) + "].sphere", s.center - glm::dvec3(s.radius),
                          "the sphere's extent");
        out.shapes.push_back(make_sphere(s.center, s.radius, m));
        break;
      case Shape::Type::Plane: {
        // The rectangle's u axis is world +X projected into the plane (+Z when
        // the normal is along X).
        check_coordinates(scene, "shapes[" + std::to_string(i) + "].plane.center", s.center, "the plane's centre");
        check_coordinates(scene, "shapes[" + std::to_string(i) + "].plane.size", glm::dvec3(s.size, 0.0),
                          "the plane's size");
        glm::dvec3 n = glm::normalize(s.normal);
        glm::dvec3 u_hint = std::abs(n.x) > 0.9 ? glm::dvec3(0, 0, 1) : glm::dvec3(1, 0, 0);
        out.shapes.push_back(make_plane(s.center, n, u_hint, s.size.x, s.size.y, m));
        break;
      }
    }
  }
  out.bvh = build_bvh(std::move(triangles));
  return out;
}

}  // namespace pyrolume::geometry
