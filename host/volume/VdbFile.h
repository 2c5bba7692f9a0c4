#pragma once
// Helpers shared by the VDB loader and `pyrolume info` (host/volume only):
// telling OpenVDB from NanoVDB files, initialising OpenVDB once, and turning a
// grid's index->world map into a GLM matrix.
#include <filesystem>
#include <string>

#include <glm/glm.hpp>
#include <nanovdb/NanoVDB.h>
#include <openvdb/math/Transform.h>

namespace pyrolume {

enum class VolumeFormat { OpenVdb, NanoVdb };

// By magic bytes, not by extension. Throws InputError for a missing file, a
// folder, or anything that is neither format.
VolumeFormat detect_volume_format(const std::filesystem::path& file);

// openvdb::initialize() exactly once per process (it registers the grid types
// that io::File needs to read anything).
void ensure_openvdb_initialized();

// The grid's affine index->world map as a column-vector GLM matrix
// (p_world = M * (i, j, k, 1)). Throws InputError for non-linear (frustum) maps.
glm::dmat4 openvdb_index_to_world(const openvdb::math::Transform& xform, const std::string& file,
                                  const std::string& grid);

// The same for a NanoVDB grid. Its Map is always affine; read the matrix off
// the images of the origin and the basis vectors, so no storage convention of
// Map::mMatD is assumed.
template <class NanoGridT>
glm::dmat4 nanovdb_index_to_world(const NanoGridT& grid) {
  const nanovdb::Vec3d o = grid.indexToWorld(nanovdb::Vec3d(0, 0, 0));
  glm::dmat4 M(1.0);
  for (int a = 0; a < 3; ++a) {
    nanovdb::Vec3d e(0, 0, 0);
    e[a] = 1;
    const nanovdb::Vec3d w = grid.indexToWorld(e);
    M[a] = glm::dvec4(w[0] - o[0], w[1] - o[1], w[2] - o[2], 0.0);
  }
  M[3] = glm::dvec4(o[0], o[1], o[2], 1.0);
  return M;
}

// "vec3s" / "Vec3f" ... : value types that hold vectors rather than scalars.
bool is_vector_type_name(const std::string& type);

}  // namespace pyrolume
