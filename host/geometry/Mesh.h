#pragma once
// Triangle meshes as loaded from OBJ files. Positions, optional normals and
// optional uvs keep their own index per corner, as OBJ stores them.
#include <array>
#include <cstdint>
#include <filesystem>
#include <glm/glm.hpp>
#include <string>
#include <vector>

namespace pyrolume::geometry {

inline constexpr uint32_t kNoIndex = 0xFFFFFFFFu;

struct Mesh {
  // One triangle corner: an index into each attribute array; normal and uv are
  // kNoIndex when the face gave none.
  struct Corner {
    uint32_t position = kNoIndex, normal = kNoIndex, uv = kNoIndex;
  };
  std::vector<glm::vec3> positions;              // scene units
  std::vector<glm::vec3> normals;                // unit length (normalised on load)
  std::vector<glm::vec2> uvs;                    // OBJ convention: (0, 0) is the image's bottom-left
  std::vector<std::array<Corner, 3>> triangles;  // counter-clockwise = front (two-sided anyway)
};

// Reads a Wavefront OBJ (tinyobjloader): every object and group, polygons
// triangulated, vertex colours and materials (mtllib/usemtl) ignored — the
// scene assigns the material. Only v/vn/vt/f/o/g lines reach the parser. A
// face with normals or uvs on only some corners drops them for the whole face.
// Missing or unreadable file, a parse error, an index out of range, a
// non-finite coordinate or no triangles at all → InputError "FILE: REASON".
Mesh load_obj(const std::filesystem::path& file);

// Applies an affine map to positions and (by the inverse transpose,
// renormalised) to normals. A map that mirrors keeps the winding as stored.
void transform_mesh(Mesh& mesh, const glm::dmat4& object_to_world);

}  // namespace pyrolume::geometry
