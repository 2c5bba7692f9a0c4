#pragma once
// Building the DenseGrid a loader returns from a grid's active values (the
// OpenVDB and NanoVDB readers of volume/VdbLoader.cpp share it): what each
// value becomes, the device, size and host-memory checks made before the
// dense array exists, and the index maps with the medium's transform on top
// (docs/volumes.md).
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "util/Error.h"
#include "util/Memory.h"
#include "volume/DenseGrid.h"
#include "volume/VolumeOptions.h"

namespace pyrolume {

struct SparseGrid;

namespace dense_build {

enum class Role { Density, Temperature };

// "density grid \"NAME\"" / "temperature grid \"NAME\"": the key of a grid's errors.
std::string role_key(Role role, const std::string& grid);

// The most texels one dense grid may have (set_max_dense_texels, VdbLoader.h).
extern uint64_t max_dense_texels;
constexpr uint64_t kHostBytesPerTexel = 12;  // 4 (float array) + 4 (texture copy) + 4 (its upload)

inline int64_t floor_div(int64_t a, int64_t k) { return a >= 0 ? a / k : -((-a + k - 1) / k); }

// What every loader keeps of a grid's values, dense or sparse (docs/volumes.md):
// NaN/Inf -> 0 and negative density -> 0, each counted for the warnings, and
// the range of what is kept.
struct ValueRules {
  bool clamp_negative;
  uint64_t nonfinite = 0, negative = 0;
  float lo = std::numeric_limits<float>::infinity(), hi = -std::numeric_limits<float>::infinity();

  // One active value, standing for `voxels` voxels (a tile covers many).
  float apply(double v, uint64_t voxels = 1) {
    float f = float(v);
    if (!std::isfinite(f)) {  // NaN, Inf, or a double beyond float range
      nonfinite += voxels;
      f = 0.0f;
    } else if (f < 0.0f && clamp_negative) {
      negative += voxels;
      f = 0.0f;
    }
    lo = std::min(lo, f);
    hi = std::max(hi, f);
    return f;
  }

  void set_range(DenseGrid& out) const {
    if (lo > hi) return;  // nothing was active
    out.min_value = lo;
    out.max_value = hi;
  }
};

// Fills a DenseGrid from active voxels. With downsample k, coarse voxel J
// averages the k^3 fine voxels k*J .. k*J + k-1 (inactive ones count as the
// background 0); its centre, the mean of the fine centres, is fine index
// k*J + (k-1)/2, which index_map() returns.
class DenseBuilder {
 public:
  DenseBuilder(DenseGrid& out, const glm::i64vec3& bmin, const glm::i64vec3& bmax, int k, bool clamp_negative,
               const std::string& file, Role role, const DenseLimits& limits);

  void add(int64_t i, int64_t j, int64_t k, double v) {
    const float f = rules.apply(v);
    if (f == 0.0f) return;
    const int64_t x = floor_div(i, k_) - out_.origin.x, y = floor_div(j, k_) - out_.origin.y,
                  z = floor_div(k, k_) - out_.origin.z;
    out_.values[(size_t(z) * size_t(out_.dims.y) + size_t(y)) * size_t(out_.dims.x) + size_t(x)] += f;
  }

  // Every voxel of the box lo..hi (inclusive; an active tile).
  void add_box(const glm::i64vec3& lo, const glm::i64vec3& hi, double v) {
    for (int64_t k = lo.z; k <= hi.z; ++k)
      for (int64_t j = lo.y; j <= hi.y; ++j)
        for (int64_t i = lo.x; i <= hi.x; ++i) add(i, j, k, v);
  }

  void finish() {
    if (k_ > 1) {
      const float w = 1.0f / float(k_ * k_ * k_);
      for (float& v : out_.values) v *= w;
    }
    rules.set_range(out_);
  }

  // Coarse index -> fine index (identity for k = 1).
  glm::dmat4 index_map() const {
    glm::dmat4 D = glm::translate(glm::dmat4(1.0), glm::dvec3(0.5 * (k_ - 1)));
    return glm::scale(D, glm::dvec3(double(k_)));
  }

  ValueRules rules;

 private:
  DenseGrid& out_;
  int k_;
};

// An allocation that failed inside OpenVDB or NanoVDB while a grid was read:
// std::bad_alloc, or the std::runtime_error NanoVDB's HostBuffer throws for
// it ("Pool::Pool malloc failed"), which named neither file nor grid. The
// checks before each large allocation (DenseBuilder, require_sparse_memory,
// the grid's size before nanovdb::io reads it) should leave nothing for this
// to catch; it names the file and grid when a smaller allocation still fails.
template <class F>
auto within_memory(const std::string& file, const std::string& key, F&& read) -> decltype(read()) {
  auto ran_out = [&] {
    return input_error(file, key, "memory ran out while reading it (" + format_bytes(memory_available_bytes()) +
                                      " left to this process); give it more memory or add \"downsample\": k to the medium");
  };
  try {
    return read();
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw ran_out();
  } catch (const std::runtime_error& e) {
    const std::string w = e.what();
    if (w.rfind("Pool::", 0) == 0 && (w.find("malloc failed") != std::string::npos ||
                                      w.find("insufficient memory") != std::string::npos ||
                                      w.find("allocation failed") != std::string::npos))
      throw ran_out();
    throw;
  }
}

// The medium's transform on top of the grid's map, after the source's voxel
// placement (VolumeOptions::index_offset).
glm::dmat4 placed(const VolumeOptions& m, const glm::dmat4& grid_to_world);

// A filled dense grid: its counts reported, its index maps set and checked.
DenseGrid finish_grid(DenseBuilder& b, DenseGrid& out, const glm::dmat4& grid_to_world, const VolumeOptions& m,
                      Role role, const std::string& file, std::vector<std::string>& warnings);

// The same for a sparse grid whose active voxels span lo..hi: the box the
// dense texture would have (one texel of padding each side), the tree kept.
DenseGrid finish_sparse(DenseGrid& out, std::shared_ptr<SparseGrid> sparse, const glm::i64vec3& lo,
                        const glm::i64vec3& hi, const ValueRules& rules, const glm::dmat4& grid_to_world,
                        const VolumeOptions& m, Role role, const std::string& file, std::vector<std::string>& warnings);

// A grid with no active voxels: no texels, only its index maps, and a warning.
DenseGrid empty_grid(std::string name, const glm::dmat4& grid_to_world, const VolumeOptions& m, Role role,
                     const std::string& file, std::vector<std::string>& warnings);

}  // namespace dense_build
}  // namespace pyrolume
