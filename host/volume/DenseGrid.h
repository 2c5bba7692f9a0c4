#pragma once
// One VDB grid copied into a dense array over its active bounding box: the CPU
// image of the 3D texture the GPU samples. Index space is OpenVDB's: voxel ijk's
// value sits at the integer index point ijk (cell-centred data, the convention of
// openvdb::tools::BoxSampler), so a texel centre is an integer index coordinate.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace pyrolume {

struct SparseGrid;

struct DenseGrid {
  std::string name;              // grid name in the file
  glm::ivec3 dims{0};            // texels, INCLUDING one voxel of zero padding on every side
  glm::ivec3 origin{0};          // index coordinate of texel (0,0,0) = active bbox min - 1
  glm::dmat4 index_to_world{1};  // the grid's affine index->world map with the medium transform on top
  glm::dmat4 world_to_index{1};
  std::vector<float> values;     // dims.x*dims.y*dims.z, x fastest, then y, then z; background 0
  float min_value = 0, max_value = 0;  // over active voxels (after NaN/neg handling)
  // Set for a grid kept sparse (texture_format "sparse", volume/SparseGrid.h):
  // `values` stays empty and texel() reads the tree; dims and origin describe
  // the same padded box as a dense grid's, so texel space is the same.
  std::shared_ptr<const SparseGrid> sparse;
  bool empty() const { return values.empty() && !sparse; }
  bool is_sparse() const { return bool(sparse); }

  size_t texel_count() const { return size_t(dims.x) * size_t(dims.y) * size_t(dims.z); }
  // Texel (i,j,k) of the array, 0 <= i < dims.x etc.
  float texel(int i, int j, int k) const {
    if (sparse) return sparse_texel(i, j, k);
    return values[(size_t(k) * size_t(dims.y) + size_t(j)) * size_t(dims.x) + size_t(i)];
  }
  float sparse_texel(int i, int j, int k) const;
  // The largest value stored (≥ 0; NaN skipped): a bound on every lookup.
  double max_texel() const;

  // Trilinear lookup at a world point exactly as the GPU does it with a sampler3D
  // (texel centres at integer index coords; OpenVDB BoxSampler convention: value at
  // integer index ijk is the voxel's value), 0 outside.
  double sample_world(const glm::dvec3& p) const;
  double sample_index(const glm::dvec3& index_pos) const;
  // World-space AABB of the texture's support (for ray bounds).
  void world_bounds(glm::dvec3& lo, glm::dvec3& hi) const;
};

struct VolumeGrids {
  DenseGrid density;
  std::optional<DenseGrid> temperature;
  std::vector<std::string> warnings;  // one line each, for stderr
  size_t tree_mem_bytes = 0;          // memUsage() of the sparse trees read (freed before return)
};

// What the device that will sample a dense grid allows (0 = no limit): the
// loader checks a grid's dimensions against it before allocating the dense
// array, so an oversized grid is one clear error instead of gigabytes of
// host memory followed by the same error.
struct DenseLimits {
  uint32_t max_dim = 0;     // maxImageDimension3D
  uint64_t max_bytes = 0;   // maxMemoryAllocationSize (checked at 2 B per texel, R16F's size)
};

// Bytes the dense texture takes on the device: 2 per texel as R16F, 4 as R32F.
size_t dense_bytes(const DenseGrid& g, bool half);

}  // namespace pyrolume
