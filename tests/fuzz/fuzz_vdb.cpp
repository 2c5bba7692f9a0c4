// What a user's .vdb / .nvdb goes through: `pyrolume info` (metadata only, and
// with --values every grid read) and the renderer's load_volume (format
// detection by magic bytes, grid listing, reading the chosen grids into
// dense arrays).
#include <cstdint>

#include "fuzz/FuzzSupport.h"
#include "fuzz/VolumeFuzz.h"
#include "scene/MediumVolume.h"
#include "volume/VdbLoader.h"

using namespace pyrolume;

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  // 2^24 texels (64 MiB as float): larger dense grids are legitimately large
  // inputs (a few bytes of active tiles describe them), not corrupt ones.
  set_max_dense_texels(uint64_t(1) << 24);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path& path = fuzz::write_scratch(data, size, ".vdb");
  const std::string file = path.string();
  fuzz::run_info_both_ways(path, file);
  Medium m;
  m.type = Medium::Type::Vdb;
  m.file = path;
  // Default grid names ("density", then "temperature"/"heat"/"flame"), as a
  // scene without density_grid/temperature_grid asks for.
  try {
    VolumeGrids g = load_volume(m, /*need_temperature=*/true);
    (void)g;
  } catch (const InputError& e) {
    fuzz::check_input_error(e, file);
  }
  return 0;
}
