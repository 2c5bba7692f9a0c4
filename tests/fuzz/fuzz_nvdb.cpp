// What a user's .nvdb goes through (docs/robustness.md "Forged NanoVDB
// trees"): `pyrolume info` with and without --values, and load_volume into a
// dense texture and kept sparse, where the tree is processed in place and
// then walked as the backends walk it (the leaf and tile tables the Vulkan
// backend uploads, the lookups the CPU reference makes). fuzz_vdb reaches
// .nvdb files too, but only with texture_format "auto"; here both paths run
// on every input.
#include <cstdint>

#include "fuzz/FuzzSupport.h"
#include "fuzz/VolumeFuzz.h"
#include "scene/MediumVolume.h"
#include "volume/SparseGrid.h"
#include "volume/VdbLoader.h"

using namespace pyrolume;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // As fuzz_vdb: a few bytes of active tiles describe legitimately huge
  // volumes, dense (2^24 texels, 64 MiB as float) or sparse (2^16 leaves,
  // about 280 MiB while built); larger ones are refused, not allocated.
  set_max_dense_texels(uint64_t(1) << 24);
  set_max_sparse_leaves(uint64_t(1) << 16);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path& path = fuzz::write_scratch(data, size, ".nvdb");
  const std::string file = path.string();
  fuzz::run_info_both_ways(path, file);
  for (TextureFormat format : {TextureFormat::R32F, TextureFormat::Sparse}) {
    Medium m;
    m.type = Medium::Type::Vdb;
    m.file = path;
    m.texture_format = format;
    try {
      VolumeGrids g = load_volume(m, /*need_temperature=*/true);
      for (const DenseGrid* grid : {&g.density, g.temperature ? &*g.temperature : nullptr}) {
        if (!grid || !grid->sparse) continue;
        const SparseGrid& s = *grid->sparse;
        float sum = 0.0f;
        s.for_each_leaf([&](const glm::ivec3& o, uint64_t offset) {
          if (offset + 512 * sizeof(float) > s.bytes()) std::abort();  // the GPU reads the values there
          sum += s.value(o);
        });
        s.for_each_tile([&](const glm::ivec3& o, int, float v) { sum += v + s.value(o); });
        sum += float(s.sample_index(glm::dvec3(grid->origin) + glm::dvec3(grid->dims) * 0.5));
        (void)sum;
      }
    } catch (const InputError& e) {
      fuzz::check_input_error(e, file);
    }
  }
  return 0;
}
