#pragma once
// Shared helpers for the ctest suites: run the CLI, make temp folders, write files.
#include <cstdint>
#include <filesystem>
#include <string>

namespace pyrolume::test {

// Linked with AddressSanitizer (tools/sanitize): such a process, and the CLI
// it starts, cannot run under `ulimit -v` (the shadow memory reserves
// terabytes of address space), and byte-by-byte sweeps of damaged files run
// ~7x slower, so they sample fewer positions there (the fuzzers cover the
// rest under the sanitizers). Asked at run time: the sanitizer build links
// the test files the gcc build compiled (docs/robustness.md "Sanitizers").
bool address_sanitizer();

// The pyrolume binary the tests run: $PYROLUME_BIN when set (the sanitizer
// build's ctest sets its own CLI there), else the one built beside the tests.
const char* pyrolume_bin();

struct CliResult {
  int status = -1;  // exit status of the pyrolume binary
  std::string out, err;
};

// Runs pyrolume_bin() with the given argument string (shell-quoted by the caller).
CliResult run_cli(const std::string& args);
// The same with address space limited to `kib` KiB (`ulimit -v`), as a render
// farm limits a job: what a memory check must refuse before allocating.
CliResult run_cli_with_memory_limit(uint64_t kib, const std::string& args);

// A fresh, empty folder under the system temp dir, unique per test; removed
// when the test process exits (kept with PYROLUME_KEEP_TEMP=1).
std::filesystem::path temp_dir(const std::string& tag);

void write_file(const std::filesystem::path& p, const std::string& text);
std::string read_file(const std::filesystem::path& p);

// The shared data folder (PYROLUME_SHARED_DATA, else the one beside the
// checkout), or empty if absent.
std::filesystem::path shared_data_dir();

// Its vdb/ folder (the real exports the realdata tests read in place), or
// empty if absent; a test then skips with kRealVdbAbsent.
std::filesystem::path real_vdb_dir();
inline constexpr const char* kRealVdbAbsent =
    "the shared data folder's vdb/ is absent (set PYROLUME_SHARED_DATA to the data folder to run these)";

}  // namespace pyrolume::test
