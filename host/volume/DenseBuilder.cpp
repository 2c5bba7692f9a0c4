#include "volume/DenseBuilder.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>

#include "volume/SparseGrid.h"

namespace pyrolume::dense_build {

uint64_t max_dense_texels = uint64_t(1) << 32;

std::string role_key(Role role, const std::string& grid) {
  return std::string(role == Role::Density ? "density" : "temperature") + " grid \"" + grid + "\"";
}

DenseBuilder::DenseBuilder(DenseGrid& out, const glm::i64vec3& bmin, const glm::i64vec3& bmax, int k,
                           bool clamp_negative, const std::string& file, Role role, const DenseLimits& limits)
    : rules{clamp_negative}, out_(out), k_(k) {
  auto dims_at = [&](int64_t kk, glm::i64vec3* lo) {
    glm::i64vec3 cmin, cmax;
    for (int a = 0; a < 3; ++a) {
      cmin[a] = floor_div(bmin[a], kk);
      cmax[a] = floor_div(bmax[a], kk);
    }
    if (lo) *lo = cmin;
    return glm::i64vec3(cmax - cmin + int64_t(3));  // + one padding texel each side
  };
  // The smallest downsample from k up to the key's maximum, 64, whose dims
  // pass `ok` (the suggestion in an error); 65 where none does.
  auto smallest_fitting = [&](auto&& ok) {
    int64_t suggest = k;
    while (suggest <= 64 && !ok(dims_at(suggest, nullptr))) ++suggest;
    return suggest;
  };
  glm::i64vec3 cmin;
  const glm::i64vec3 dims = dims_at(k, &cmin);
  const uint64_t texels = uint64_t(dims.x) * uint64_t(dims.y) * uint64_t(dims.z);
  // The device's limits, before anything is allocated; the suggestion is
  // the smallest downsample that fits them.
  auto fits = [&](const glm::i64vec3& d) {
    const uint64_t n = uint64_t(d.x) * uint64_t(d.y) * uint64_t(d.z);
    return (limits.max_dim == 0 || std::max({d.x, d.y, d.z}) <= int64_t(limits.max_dim)) &&
           (limits.max_bytes == 0 || 2 * n <= limits.max_bytes);
  };
  if (!fits(dims)) {
    const int64_t suggest = smallest_fitting(fits);
    std::ostringstream s;
    s << dims.x << "x" << dims.y << "x" << dims.z << " texels (with downsample " << k << ") exceed ";
    if (limits.max_dim != 0 && std::max({dims.x, dims.y, dims.z}) > int64_t(limits.max_dim))
      s << "this device's 3D texture limit of " << limits.max_dim << " per axis";
    else
      s << "what this device allows in one allocation (" << (limits.max_bytes >> 20) << " MiB at 2 B per texel)";
    if (suggest <= 64) s << "; add \"downsample\": " << suggest << " to the medium";
    else s << "; even \"downsample\": 64 does not fit: crop the grid";
    throw input_error(file, role_key(role, out.name), s.str());
  }
  // 2^32 texels is 16 GiB as float: past what any host or device here holds,
  // and texel offsets would overflow 32-bit shader arithmetic.
  if (dims.x > (1 << 30) || dims.y > (1 << 30) || dims.z > (1 << 30) || texels > max_dense_texels) {
    std::ostringstream s;
    s << "active bounding box of " << dims.x - 2 << " x " << dims.y - 2 << " x " << dims.z - 2
      << " voxels is too large for a dense texture; use \"downsample\": k (box filter by k)";
    throw input_error(file, role_key(role, out.name), s.str());
  }
  // The host's memory, before the array exists: the dense floats, the
  // texture copy the renderers store beside them and its upload (R32F at
  // worst), kHostBytesPerTexel in all. Past it the grid is refused with the
  // downsample that would fit, not allocated into std::bad_alloc.
  const uint64_t room = memory_available_bytes();
  auto host_fits = [&](const glm::i64vec3& d) {
    return room == 0 || uint64_t(d.x) * uint64_t(d.y) * uint64_t(d.z) * kHostBytesPerTexel <= room;
  };
  if (!host_fits(dims)) {
    const int64_t suggest = smallest_fitting(host_fits);
    std::ostringstream s;
    s << dims.x << "x" << dims.y << "x" << dims.z << " texels (with downsample " << k << ") need "
      << format_bytes(texels * kHostBytesPerTexel) << " of host memory (" << kHostBytesPerTexel
      << " B per texel: the dense array, its texture copy and upload), more than the " << format_bytes(room)
      << " this process can still allocate";
    if (suggest <= 64) s << "; add \"downsample\": " << suggest << " to the medium";
    throw input_error(file, role_key(role, out.name), s.str());
  }
  out_.origin = glm::ivec3(cmin - int64_t(1));
  out_.dims = glm::ivec3(dims);
  out_.values.assign(texels, 0.0f);
}

namespace {

// The renderers map rays into the grid with these matrices (the GPU in
// float): entries beyond kMaxMapEntry, or non-finite ones, lose the grid and
// turn samples non-finite (a transform scale of 1e-300 gave voxels of 1e-300
// and a world-to-index map of 1e300). Voxels from 1e-15 to 1e15 scene units pass.
constexpr double kMaxMapEntry = 1e15;

void check_index_maps(const DenseGrid& g, const std::string& file, Role role) {
  auto within = [](const glm::dmat4& M) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        if (!(std::abs(M[c][r]) <= kMaxMapEntry)) return false;
    return true;
  };
  if (within(g.index_to_world) && within(g.world_to_index)) return;
  std::ostringstream s;
  s << "its index-to-world map with the medium's transform on top is degenerate or beyond float range (a voxel is "
    << glm::length(glm::dvec3(g.index_to_world[0])) << " units along x; at most " << kMaxMapEntry
    << " either way): check the medium's transform.scale";
  throw input_error(file, role_key(role, g.name), s.str());
}

void report_counts(const ValueRules& r, const std::string& file, Role role, const std::string& grid,
                   std::vector<std::string>& warnings) {
  if (r.nonfinite)
    warnings.push_back(file + ": " + role_key(role, grid) + ": " + std::to_string(r.nonfinite) +
                       " NaN/Inf voxels treated as 0");
  if (r.negative)
    warnings.push_back(file + ": " + role_key(role, grid) + ": " + std::to_string(r.negative) +
                       " negative density voxels clamped to 0");
}

void set_index_maps(DenseGrid& out, const glm::dmat4& index_to_world, const std::string& file, Role role) {
  out.index_to_world = index_to_world;
  out.world_to_index = glm::inverse(out.index_to_world);
  check_index_maps(out, file, role);
}

}  // namespace

glm::dmat4 placed(const VolumeOptions& m, const glm::dmat4& grid_to_world) {
  return m.transform * grid_to_world * glm::translate(glm::dmat4(1.0), glm::dvec3(m.index_offset));
}

DenseGrid finish_grid(DenseBuilder& b, DenseGrid& out, const glm::dmat4& grid_to_world, const VolumeOptions& m,
                      Role role, const std::string& file, std::vector<std::string>& warnings) {
  b.finish();
  report_counts(b.rules, file, role, out.name, warnings);
  set_index_maps(out, placed(m, grid_to_world) * b.index_map(), file, role);
  return std::move(out);
}

DenseGrid finish_sparse(DenseGrid& out, std::shared_ptr<SparseGrid> sparse, const glm::i64vec3& lo,
                        const glm::i64vec3& hi, const ValueRules& rules, const glm::dmat4& grid_to_world,
                        const VolumeOptions& m, Role role, const std::string& file, std::vector<std::string>& warnings) {
  report_counts(rules, file, role, out.name, warnings);
  out.sparse = std::move(sparse);
  out.origin = glm::ivec3(lo - int64_t(1));
  out.dims = glm::ivec3(hi - lo + int64_t(3));
  rules.set_range(out);
  set_index_maps(out, placed(m, grid_to_world), file, role);
  return std::move(out);
}

DenseGrid empty_grid(std::string name, const glm::dmat4& grid_to_world, const VolumeOptions& m, Role role,
                     const std::string& file, std::vector<std::string>& warnings) {
  DenseGrid out;
  out.name = std::move(name);
  set_index_maps(out, placed(m, grid_to_world), file, role);
  warnings.push_back(file + ": " + role_key(role, out.name) + ": empty grid (no active voxels): " +
                     (role == Role::Density ? "renders as no medium" : "the medium does not emit"));
  return out;
}

}  // namespace pyrolume::dense_build
