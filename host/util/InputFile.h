#pragma once
// Reading a whole input file (scene JSON, OBJ, image, checkpoint) into memory,
// with its size checked before the buffer grows: against a stated limit for
// that kind of file and against what this process can still allocate
// (util/Memory.h). A file that is not a regular one (/dev/zero, a FIFO, a
// process substitution) is read in chunks and refused once it passes the
// limit, so nothing reads forever. Errors are InputError naming the file.
#include <cstdint>
#include <filesystem>
#include <string>

namespace pyrolume {

// Stated limits, one per kind of input (docs/robustness.md "Limits").
inline constexpr uint64_t kMaxSceneBytes = uint64_t(64) << 20;       // scene JSON
inline constexpr uint64_t kMaxObjBytes = uint64_t(4) << 30;          // OBJ text
inline constexpr uint64_t kMaxImageBytes = uint64_t(4) << 30;        // EXR, PNG, HDR, ... (textures, environment maps)

// The file's bytes. `what` names the kind in messages ("scene", "OBJ mesh",
// "image"); `memory_factor` is how many times its size the reader will hold
// while parsing (the text plus what is built from it), checked against memory
// before reading. Throws InputError "FILE: REASON" for a missing, unreadable,
// folder or oversized file.
std::string read_input_file(const std::filesystem::path& file, uint64_t max_bytes, const std::string& what,
                            double memory_factor = 1.0);

}  // namespace pyrolume
