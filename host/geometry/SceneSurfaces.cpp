#include "geometry/SceneSurfaces.h"

#include <map>

#include "geometry/Mesh.h"
#include "geometry/Triangle.h"
#include "volume/VdbLoader.h"

namespace pyrolume::geometry {

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
        auto tris = triangles_of(mesh, m, uint32_t(i), uint32_t(triangles.size()));
        triangles.insert(triangles.end(), tris.begin(), tris.end());
        break;
      }
      case Shape::Type::Sphere:
        out.shapes.push_back(make_sphere(s.center, s.radius, m));
        break;
      case Shape::Type::Plane: {
        // The rectangle's u axis is world +X projected into the plane (+Z when
        // the normal is along X).
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
