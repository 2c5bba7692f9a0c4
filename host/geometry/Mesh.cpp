#include "geometry/Mesh.h"

#include <cerrno>
#include <cfloat>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>

// The only translation unit that compiles tinyobjloader (header-only use).
#define TINYOBJLOADER_IMPLEMENTATION
#include <tiny_obj_loader.h>

#include "util/Error.h"
#include "util/InputFile.h"

namespace pyrolume::geometry {
namespace {

// tinyobjloader's messages end in newlines and may hold several lines: keep
// the first, so the error stays one line.
std::string first_line(const std::string& text) {
  size_t start = text.find_first_not_of(" \t\r\n");
  if (start == std::string::npos) return "parse error";
  size_t end = text.find_first_of("\r\n", start);
  return text.substr(start, end == std::string::npos ? std::string::npos : end - start);
}

bool finite(float x) { return std::isfinite(x); }

// Every number of a v, vn or vt statement must be finite as a float.
// tinyobjloader reads "nan" and "inf" as 0 without a word (its number parser
// knows only digits) and 1e39 as an infinite float, so they are refused here
// with their line. Tokens that are not numbers at all are left to it.
void check_finite_numbers(const std::string& text, size_t begin, size_t end, size_t line, const std::string& name) {
  for (size_t i = begin; i < end;) {
    const size_t a = text.find_first_not_of(" \t", i);
    if (a == std::string::npos || a >= end) break;
    size_t b = text.find_first_of(" \t", a);
    if (b == std::string::npos || b > end) b = end;
    const std::string token(text, a, b - a);
    char* stop = nullptr;
    errno = 0;
    const double v = std::strtod(token.c_str(), &stop);
    if (stop == token.c_str() + token.size() && !(std::abs(v) <= double(FLT_MAX)))
      throw input_error(name, "line " + std::to_string(line),
                        "\"" + token + "\" is not a finite number (coordinates must be finite floats)");
    i = b;
  }
}

// Keeps only the statements a mesh needs (v, vn, vt, f, o, g) and blanks every
// other line, so line numbers in tinyobjloader's messages still match the
// file. What is dropped (materials, smoothing groups, lines, points, skin
// weights, tags) is ignored by pyrolume anyway, and tinyobjloader parses some
// of it unsafely: "vw 1 1e35 0.5" converts a float joint id to int out of
// range (undefined behaviour; fuzz_obj found it). Line ends are \n, \r\n or a
// lone \r, as tinyobjloader's own line splitter reads them.
std::string mesh_statements(const std::string& text, const std::string& name) {
  std::string out;
  out.reserve(text.size());
  size_t i = 0, line = 0;
  while (i < text.size()) {
    ++line;
    size_t end = text.find_first_of("\r\n", i);
    if (end == std::string::npos) end = text.size();
    size_t a = text.find_first_not_of(" \t", i);  // stops at the line end at the latest
    if (a == std::string::npos) a = end;
    size_t b = text.find_first_of(" \t", a);
    if (b == std::string::npos || b > end) b = end;
    const std::string_view keyword(text.data() + a, b - a);
    if (keyword == "v" || keyword == "vn" || keyword == "vt") check_finite_numbers(text, b, end, line, name);
    if (keyword == "v" || keyword == "vn" || keyword == "vt" || keyword == "f" || keyword == "o" || keyword == "g")
      out.append(text, i, end - i);
    out.push_back('\n');
    i = end;  // past one line end: \r\n, \r or \n
    if (i < text.size()) i += (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ? 2 : 1;
  }
  return out;
}

}  // namespace

Mesh load_obj(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw input_error(name, "", "no such file");
  // The text, its filtered copy and tinyobjloader's arrays: about four times
  // the file's size at once.
  const std::string text = read_input_file(file, kMaxObjBytes, "OBJ", 4.0);

  // From memory, with no material reader: materials are ignored anyway, and
  // reading them would open whatever path a `mtllib` line names (a FIFO or
  // "mtllib /dev/zero" would block or read forever).
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  std::istringstream stream(mesh_statements(text, name));
  const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &stream, /*readMatFn=*/nullptr,
                                   /*triangulate=*/true, /*default_vcols_fallback=*/false);
  if (!ok) throw input_error(name, "", "not a valid OBJ file: " + first_line(err));
  // A mesh whose first line already failed to parse often "succeeds" with
  // errors recorded; treat any error text as fatal.
  if (!err.empty()) throw input_error(name, "", "not a valid OBJ file: " + first_line(err));

  // tinyobjloader skips a polygon with an out-of-range index with only a
  // warning: a mesh with holes must not render silently.
  if (warn.find("invalid vertex index") != std::string::npos)
    throw input_error(name, "", "a face uses a vertex index out of range");

  Mesh mesh;
  const size_t np = attrib.vertices.size() / 3, nn = attrib.normals.size() / 3, nt = attrib.texcoords.size() / 2;
  mesh.positions.resize(np);
  for (size_t i = 0; i < np; ++i) {
    glm::vec3 p(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
    if (!finite(p.x) || !finite(p.y) || !finite(p.z))
      throw input_error(name, "", "vertex " + std::to_string(i + 1) + " has a non-finite coordinate");
    mesh.positions[i] = p;
  }
  mesh.normals.resize(nn);
  for (size_t i = 0; i < nn; ++i) {
    glm::vec3 n(attrib.normals[3 * i], attrib.normals[3 * i + 1], attrib.normals[3 * i + 2]);
    float len = glm::length(n);
    // A zero or broken normal is unusable for shading; fall back to the
    // geometric normal for faces that use it (their normal index is dropped).
    mesh.normals[i] = (std::isfinite(len) && len > 0.0f) ? n / len : glm::vec3(0.0f);
  }
  mesh.uvs.resize(nt);
  for (size_t i = 0; i < nt; ++i) {
    glm::vec2 uv(attrib.texcoords[2 * i], attrib.texcoords[2 * i + 1]);
    if (!finite(uv.x) || !finite(uv.y))
      throw input_error(name, "", "texture coordinate " + std::to_string(i + 1) + " is not finite");
    mesh.uvs[i] = uv;
  }

  for (const tinyobj::shape_t& shape : shapes) {
    const auto& idx = shape.mesh.indices;
    size_t offset = 0;
    for (size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      const size_t fv = shape.mesh.num_face_vertices[f];
      if (fv != 3) {
        // triangulate = true only leaves degenerate faces (1-2 corners): skip them.
        offset += fv;
        continue;
      }
      std::array<Mesh::Corner, 3> tri;
      bool all_normals = true, all_uvs = true;
      for (size_t k = 0; k < 3; ++k) {
        const tinyobj::index_t& ix = idx[offset + k];
        if (ix.vertex_index < 0 || size_t(ix.vertex_index) >= np)
          throw input_error(name, "",
                            "face " + std::to_string(f + 1) + " of '" + shape.name + "' uses vertex " +
                                std::to_string(ix.vertex_index + 1) + " of " + std::to_string(np));
        tri[k].position = uint32_t(ix.vertex_index);
        if (ix.normal_index >= 0 && size_t(ix.normal_index) < nn &&
            mesh.normals[size_t(ix.normal_index)] != glm::vec3(0.0f))
          tri[k].normal = uint32_t(ix.normal_index);
        else
          all_normals = false;
        if (ix.normal_index >= 0 && size_t(ix.normal_index) >= nn)
          throw input_error(name, "",
                            "face " + std::to_string(f + 1) + " uses normal " + std::to_string(ix.normal_index + 1) +
                                " of " + std::to_string(nn));
        if (ix.texcoord_index >= 0 && size_t(ix.texcoord_index) < nt)
          tri[k].uv = uint32_t(ix.texcoord_index);
        else
          all_uvs = false;
        if (ix.texcoord_index >= 0 && size_t(ix.texcoord_index) >= nt)
          throw input_error(name, "",
                            "face " + std::to_string(f + 1) + " uses texture coordinate " +
                                std::to_string(ix.texcoord_index + 1) + " of " + std::to_string(nt));
      }
      for (auto& c : tri) {
        if (!all_normals) c.normal = kNoIndex;
        if (!all_uvs) c.uv = kNoIndex;
      }
      mesh.triangles.push_back(tri);
      offset += fv;
    }
  }
  if (mesh.triangles.empty()) throw input_error(name, "", "no triangles (not an OBJ mesh, or only points and lines)");
  return mesh;
}

void transform_mesh(Mesh& mesh, const glm::dmat4& object_to_world) {
  const glm::dmat3 normal_map = glm::transpose(glm::inverse(glm::dmat3(object_to_world)));
  for (glm::vec3& p : mesh.positions) p = glm::vec3(object_to_world * glm::dvec4(glm::dvec3(p), 1.0));
  for (glm::vec3& n : mesh.normals) {
    if (n == glm::vec3(0.0f)) continue;
    n = glm::vec3(glm::normalize(normal_map * glm::dvec3(n)));
  }
}

}  // namespace pyrolume::geometry
