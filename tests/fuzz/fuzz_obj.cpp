// OBJ meshes: load_obj (tinyobjloader parse, then index and finiteness checks).
#include <cstdint>

#include "fuzz/FuzzSupport.h"
#include "geometry/Mesh.h"

using namespace pyrolume;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path& path = fuzz::write_scratch(data, size, ".obj");
  try {
    const geometry::Mesh mesh = geometry::load_obj(path);
    // What the BVH builder and the GPU upload rely on.
    for (const auto& tri : mesh.triangles)
      for (const auto& c : tri) {
        if (c.position >= mesh.positions.size() ||
            (c.normal != geometry::kNoIndex && c.normal >= mesh.normals.size()) ||
            (c.uv != geometry::kNoIndex && c.uv >= mesh.uvs.size()))
          __builtin_trap();
      }
  } catch (const InputError& e) {
    fuzz::check_input_error(e, path.string());
  }
  return 0;
}
