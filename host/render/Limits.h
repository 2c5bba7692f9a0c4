#pragma once
// Size checks made before anything is allocated (issue 10 "limits"): a render
// whose per-pixel accumulation cannot fit is bad input (exit 2) with one line
// naming the keys, not an allocation failure or a driver error halfway in.
#include <cstdint>
#include <string>

#include "util/Memory.h"

namespace pyrolume {

// Throws InputError "FILE: film.width x film.height: ..." when width·height
// pixels of bytes_per_pixel exceed `limit` bytes (`limit_what` says whose
// limit, e.g. "this device's maxStorageBufferRange"). 64-bit arithmetic.
void check_accumulation_size(const std::string& file, int width, int height, uint64_t bytes_per_pixel,
                             uint64_t limit, const std::string& limit_what);

// The same against what this process can still allocate (util/Memory.h:
// MemAvailable, `ulimit -v`, the cgroup's limit).
void check_accumulation_fits_memory(const std::string& file, int width, int height, uint64_t bytes_per_pixel);

}  // namespace pyrolume
