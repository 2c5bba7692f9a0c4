#include "util/Memory.h"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>

#include "util/Error.h"

namespace pyrolume {
namespace {

constexpr uint64_t kUnknown = std::numeric_limits<uint64_t>::max();

// "Key:   123 kB" from a /proc file, in bytes.
uint64_t proc_kib_field(const char* file, const std::string& key) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line))
    if (line.compare(0, key.size(), key) == 0 && line.size() > key.size() && line[key.size()] == ':') {
      unsigned long long kib = 0;
      if (std::sscanf(line.c_str() + key.size() + 1, "%llu", &kib) == 1) return uint64_t(kib) * 1024;
    }
  return kUnknown;
}

// Room under an rlimit, given what the process uses of that resource now.
uint64_t rlimit_room(int resource, uint64_t used) {
  rlimit r{};
  if (::getrlimit(resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY || used == kUnknown) return kUnknown;
  return uint64_t(r.rlim_cur) > used ? uint64_t(r.rlim_cur) - used : 0;
}

uint64_t read_u64(const std::string& file) {
  std::ifstream in(file);
  std::string s;
  if (!(in >> s) || s == "max") return kUnknown;
  try {
    return std::stoull(s);
  } catch (const std::exception&) {
    return kUnknown;
  }
}

// cgroup v2 (the unified hierarchy, "0::/path" in /proc/self/cgroup):
// memory.max − memory.current of this process's group.
uint64_t cgroup_room() {
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("0::", 0) != 0) continue;
    const std::string dir = "/sys/fs/cgroup" + line.substr(3);
    const uint64_t max = read_u64(dir + "/memory.max"), current = read_u64(dir + "/memory.current");
    if (max == kUnknown || current == kUnknown) return kUnknown;
    return max > current ? max - current : 0;
  }
  return kUnknown;
}

}  // namespace

uint64_t memory_available_bytes() {
  uint64_t room = proc_kib_field("/proc/meminfo", "MemAvailable");
  if (room == kUnknown) room = physical_memory_bytes() ? physical_memory_bytes() : kUnknown;
  room = std::min(room, rlimit_room(RLIMIT_AS, proc_kib_field("/proc/self/status", "VmSize")));
  room = std::min(room, rlimit_room(RLIMIT_DATA, proc_kib_field("/proc/self/status", "VmData")));
  room = std::min(room, cgroup_room());
  return room == kUnknown ? 0 : room;
}

uint64_t physical_memory_bytes() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? uint64_t(pages) * uint64_t(page) : 0;
}

std::string format_bytes(uint64_t bytes) {
  char buf[64];
  if (bytes >= (uint64_t(1) << 30)) std::snprintf(buf, sizeof buf, "%.1f GiB", double(bytes) / double(1ull << 30));
  else if (bytes >= (uint64_t(1) << 20)) std::snprintf(buf, sizeof buf, "%.0f MiB", double(bytes) / double(1ull << 20));
  else std::snprintf(buf, sizeof buf, "%llu bytes", (unsigned long long)bytes);
  return buf;
}

void require_memory(const std::string& file, const std::string& key, const std::string& what, uint64_t bytes,
                    const std::string& hint) {
  const uint64_t room = memory_available_bytes();
  if (room == 0 || bytes <= room) return;
  throw input_error(file, key,
                    what + " needs " + format_bytes(bytes) + ", more than the " + format_bytes(room) +
                        " this process can still allocate" + (hint.empty() ? "" : " (" + hint + ")"));
}

}  // namespace pyrolume
