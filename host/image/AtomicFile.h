#pragma once
// Write-then-rename, so a failed or interrupted run never leaves a partial file at
// the destination (DESIGN.md, "Command line"). Usable for any output: images,
// stats JSON, CSV.
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>

namespace pyrolume {

// Creates a hidden temp file ".NAME.tmp-PID-N.EXT" in dest's folder, lets `write`
// fill it through a binary stream, flushes and fsyncs it, then renames it over
// dest (atomic on POSIX). If `write` throws or any step fails, the temp file is
// removed and dest is left as it was. Open/write/rename failures throw InputError
// "DEST: REASON"; an exception from `write` propagates unchanged.
void write_file_atomic(const std::filesystem::path& dest, const std::function<void(std::ostream&)>& write);

// Convenience for text outputs (stats JSON, CSV).
void write_text_atomic(const std::filesystem::path& dest, const std::string& text);

}  // namespace pyrolume
