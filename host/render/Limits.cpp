#include "render/Limits.h"

#include "util/Error.h"

namespace pyrolume {

void check_accumulation_size(const std::string& file, int width, int height, uint64_t bytes_per_pixel,
                             uint64_t limit, const std::string& limit_what) {
  const uint64_t bytes = uint64_t(uint32_t(width)) * uint64_t(uint32_t(height)) * bytes_per_pixel;
  if (limit == 0 || bytes <= limit) return;
  throw input_error(file, "film.width x film.height (or --width/--height)",
                    std::to_string(width) + "x" + std::to_string(height) + " pixels need " + format_bytes(bytes) +
                        " of accumulation (" + std::to_string(bytes_per_pixel) + " B per pixel), more than " +
                        limit_what + " (" + format_bytes(limit) + "); render a smaller image");
}

void check_accumulation_fits_memory(const std::string& file, int width, int height, uint64_t bytes_per_pixel) {
  check_accumulation_size(file, width, height, bytes_per_pixel, memory_available_bytes(),
                          "the memory this process can still allocate");
}

}  // namespace pyrolume
