#pragma once
// One grid kept sparse: a NanoVDB float tree of the voxels the dense path would
// store (the same values: NaN/Inf and, for density, negatives turned to 0,
// inactive voxels 0), uploaded to the GPU as is and sampled there through
// PNanoVDB (shaders/sparse.glsl); the CPU reference reads the same tree with
// NanoVDB's C++ accessor (docs/volumes.md "Sparse grids").
#include <cstddef>
#include <cstdint>
#include <functional>

#include <glm/glm.hpp>
#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/GridHandle.h>
#include <nanovdb/util/HostBuffer.h>

namespace pyrolume {

struct SparseGrid {
  // Exactly one float grid. Its active tiles (cubes of one value) are kept:
  // the lookups read them, and the visits below include them.
  // Mutable for move_to, which changes where the same bytes live.
  mutable nanovdb::GridHandle<nanovdb::HostBuffer> handle;

  const nanovdb::FloatGrid& grid() const { return *handle.grid<float>(); }
  // Copies the tree to `memory` (bytes() long, 32-byte aligned, outliving
  // this grid) and reads it from there from now on, its own buffer freed. The
  // Vulkan backend moves trees into mapped device memory where the device's
  // memory is host memory (lavapipe), so that each is held once.
  void move_to(void* memory) const;
  size_t bytes() const { return handle.size(); }      // what the GPU stores
  uint64_t leaf_count() const { return grid().tree().nodeCount(0); }
  uint64_t active_voxels() const { return grid().activeVoxelCount(); }

  // The value at index ijk (0 where no leaf holds it).
  float value(const glm::ivec3& ijk) const;
  // Trilinear at an index position, OpenVDB's BoxSampler convention (voxel
  // ijk's value sits at the integer point ijk), 0 outside the tree.
  double sample_index(const glm::dvec3& index_pos) const;
  // f(ijk, value) for every voxel of every leaf, and of every tile, whose
  // value is not 0.
  void for_each_nonzero(const std::function<void(const glm::ivec3&, float)>& f) const;
  // f(origin, size, value) for every tile of the internal nodes whose value is
  // not 0: a cube of size³ voxels (8 or 128) from origin.
  void for_each_tile(const std::function<void(const glm::ivec3&, int, float)>& f) const;
  // f(origin, offset) for every leaf: its first voxel's index and the byte
  // offset of its 512 values (x-major: voxel (x, y, z) at 4·(64x + 8y + z))
  // in handle's buffer.
  void for_each_leaf(const std::function<void(const glm::ivec3&, uint64_t)>& f) const;
};

// Bytes of a NanoVDB float grid with these node counts (leaves, lower and
// upper internal nodes): what a sparse grid stores, to within its headers.
uint64_t nanovdb_float_bytes(uint64_t leaves, uint64_t lowers, uint64_t uppers);

}  // namespace pyrolume
