#pragma once
// Shared helpers for the ctest suites: run the CLI, make temp folders, write files.
#include <cstdint>
#include <filesystem>
#include <string>

namespace pyrolume::test {

// Linked with AddressSanitizer (tools/sanitize; CMake defines
// PYROLUME_SANITIZE, since the test files themselves are compiled without
// it): such a process, and the CLI it starts, cannot run under `ulimit -v`
// (the shadow memory reserves terabytes of address space), and byte-by-byte
// sweeps of damaged files run ~7x slower, so they sample fewer positions
// there (the fuzzers cover the rest under the sanitizers).
#if defined(PYROLUME_SANITIZE) || defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif

struct CliResult {
  int status = -1;  // exit status of the pyrolume binary
  std::string out, err;
};

// Runs PYROLUME_BIN with the given argument string (shell-quoted by the caller).
CliResult run_cli(const std::string& args);
// The same with address space limited to `kib` KiB (`ulimit -v`), as a render
// farm limits a job: what a memory check must refuse before allocating.
CliResult run_cli_with_memory_limit(uint64_t kib, const std::string& args);

// A fresh, empty folder under the system temp dir, unique per test.
std::filesystem::path temp_dir(const std::string& tag);

void write_file(const std::filesystem::path& p, const std::string& text);
std::string read_file(const std::filesystem::path& p);

// ../shared/data, or empty if absent.
std::filesystem::path shared_data_dir();

}  // namespace pyrolume::test
