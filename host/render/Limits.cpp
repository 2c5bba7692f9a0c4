#include "render/Limits.h"

#include <unistd.h>

#include <cstdio>

#include "util/Error.h"

namespace pyrolume {
namespace {
std::string mib(uint64_t bytes) {
  char buf[64];
  if (bytes >= (uint64_t(1) << 30)) std::snprintf(buf, sizeof buf, "%.1f GiB", double(bytes) / double(1ull << 30));
  else std::snprintf(buf, sizeof buf, "%.0f MiB", double(bytes) / double(1ull << 20));
  return buf;
}
}  // namespace

void check_accumulation_size(const std::string& file, int width, int height, uint64_t bytes_per_pixel,
                             uint64_t limit, const std::string& limit_what) {
  const uint64_t bytes = uint64_t(uint32_t(width)) * uint64_t(uint32_t(height)) * bytes_per_pixel;
  if (limit == 0 || bytes <= limit) return;
  throw input_error(file, "film.width x film.height (or --width/--height)",
                    std::to_string(width) + "x" + std::to_string(height) + " pixels need " + mib(bytes) +
                        " of accumulation (" + std::to_string(bytes_per_pixel) + " B per pixel), more than " +
                        limit_what + " (" + mib(limit) + "); render a smaller image");
}

uint64_t physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : 0;
}

}  // namespace pyrolume
