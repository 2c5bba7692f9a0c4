#pragma once
// Helpers shared by the VDB loader and `pyrolume info` (host/volume only):
// telling OpenVDB from NanoVDB files, initialising OpenVDB once, and turning a
// grid's index->world map into a GLM matrix.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/GridHandle.h>
#include <nanovdb/util/HostBuffer.h>
#include <openvdb/math/Transform.h>

namespace pyrolume {

enum class VolumeFormat { OpenVdb, NanoVdb };

// By magic bytes, not by extension. Throws InputError for a missing file, a
// folder, or anything that is neither format.
VolumeFormat detect_volume_format(const std::filesystem::path& file);

// Walks an OpenVDB file's framing with every length, count and offset checked
// against the file size, before OpenVDB reads it: OpenVDB trusts those numbers
// and, on a corrupt or truncated file, allocates whatever a length field says
// (gigabytes for a four-byte string), loops past the end, leaks nodes or reads
// past its buffers. Checks the header, the file and grid metadata, the grid
// descriptors and transforms and, for the grids `walk_tree` accepts (by grid
// name), the tree: root tiles and children, internal and leaf node masks and
// every compressed value chunk's size (ZIP, Blosc, raw; half or full
// precision). Trees are walked for the value types pyrolume reads or prints
// (float, double, int32, int64, vec3s, vec3d, vec3i on the standard 5-4-3
// tree); file format versions 222 (OpenVDB 3, 2014) to 224.
// Returns the names of the grids whose trees were walked; throws InputError
// naming the file, the grid and what is wrong. (docs/robustness.md, "Fuzzing")
std::vector<std::string> validate_openvdb_file(const std::filesystem::path& file,
                                               const std::function<bool(const std::string&)>& walk_tree = {});

// NanoVDB files: each segment header, grid metadata record and name, and each
// grid's stored size checked against the file before nanovdb::io reads them
// (it allocates by the stored sizes and reads names up to a NUL); only
// uncompressed grids (this build has neither Blosc nor ZIP for NanoVDB).
void validate_nanovdb_file(const std::filesystem::path& file);

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
