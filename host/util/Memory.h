#pragma once
// How much memory this process may still take, checked before a large
// allocation (docs/robustness.md "Limits"): an input that would need more is
// refused with one line naming the file, what it needs and what there is,
// instead of ending in std::bad_alloc or the kernel's OOM killer.
#include <cstdint>
#include <string>

namespace pyrolume {

// What this process can still allocate, in bytes: the least of the machine's
// MemAvailable (/proc/meminfo), the room left under RLIMIT_AS and RLIMIT_DATA
// (`ulimit -v`, `ulimit -d`: what a render farm sets) and under its cgroup's
// memory.max. 0 when none of them can be read (then nothing is checked).
uint64_t memory_available_bytes();

// The machine's physical memory in bytes (0 if unknown).
uint64_t physical_memory_bytes();

// "512 MiB", "3.2 GiB": sizes in messages.
std::string format_bytes(uint64_t bytes);

// Throws InputError "FILE: KEY: WHAT needs N, more than the M this process can
// still allocate (HINT)" when `bytes` exceeds memory_available_bytes(). KEY and
// HINT may be empty.
void require_memory(const std::string& file, const std::string& key, const std::string& what, uint64_t bytes,
                    const std::string& hint = "");

}  // namespace pyrolume
