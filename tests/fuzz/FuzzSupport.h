#pragma once
// Shared by the libFuzzer targets (tests/fuzz/fuzz_*.cpp, run by tools/fuzz).
// The loaders take paths, as a user's input does, so each input is written to
// one scratch file per process. The only failure a target accepts is the
// project's InputError, and only in its documented shape: one line that
// starts with the file's name. Anything else (another exception, a sanitizer
// report, a crash, an allocation past libFuzzer's -malloc_limit_mb) is a
// finding.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include "util/Error.h"

namespace pyrolume::fuzz {

// $TMPDIR (tools/fuzz points it at a tmpfs when there is one)/pyrolume-fuzz-PID.EXT,
// removed at exit.
inline const std::filesystem::path& scratch_path(const char* ext) {
  static const std::filesystem::path path = [ext] {
    const char* dir = std::getenv("TMPDIR");
    std::filesystem::path p = std::filesystem::path(dir && *dir ? dir : "/tmp") /
                              ("pyrolume-fuzz-" + std::to_string(getpid()) + ext);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove(scratch_path(""), ec);
    });
    return p;
  }();
  return path;
}

inline const std::filesystem::path& write_scratch(const uint8_t* data, size_t size, const char* ext) {
  const std::filesystem::path& p = scratch_path(ext);
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  out.close();
  if (!out) {
    std::fprintf(stderr, "fuzz: cannot write %s\n", p.c_str());
    std::abort();
  }
  return p;
}

// An InputError must be one line naming the file; abort (a finding) otherwise.
inline void check_input_error(const InputError& e, const std::string& file) {
  const std::string msg = e.what();
  if (msg.rfind(file, 0) != 0 || msg.find('\n') != std::string::npos) {
    std::fprintf(stderr, "fuzz: malformed InputError (must be one line starting with \"%s\"): %s\n", file.c_str(),
                 msg.c_str());
    std::abort();
  }
}

// A value a successful parse/load hands on must be finite (NaN or Inf would
// reach the renderer unnoticed).
inline void require_finite(double v, const char* what) {
  if (!std::isfinite(v)) {
    std::fprintf(stderr, "fuzz: accepted input yields a non-finite %s (%g)\n", what, v);
    std::abort();
  }
}

}  // namespace pyrolume::fuzz
