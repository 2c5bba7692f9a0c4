// Images by content (EXR via OpenEXR; PNG/HDR/... via stb_image) through the
// environment-map loader, which is read_image plus the sampling tables; OBJ
// albedo textures take the same read_image path.
#include <cstdint>

#include "fuzz/FuzzSupport.h"
#include "light/EnvironmentMap.h"

using namespace pyrolume;

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::filesystem::path& path = fuzz::write_scratch(data, size, ".exr");
  try {
    const EnvironmentMap env = EnvironmentMap::load(path);
    if (env.width() <= 0 || env.height() <= 0) __builtin_trap();
  } catch (const InputError& e) {
    fuzz::check_input_error(e, path.string());
  }
  return 0;
}
