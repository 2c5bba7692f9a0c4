#pragma once
// Checkpoints (`render --checkpoint SEC`, `--resume`; README "Using it"): a
// render's accumulation state saved next to its output as OUT.checkpoint
// (e.g. out.exr.checkpoint), written atomically, with what identifies the
// render so that a resume with another scene, size, seed or backend is refused.
//
// File layout (version 2): the line "pyrolume-checkpoint 2", one line of JSON
// (the identity, spp and the payload's size), the backend's AccumulationState
// bytes, then the FNV-1a 64 checksum of everything before it, both lines
// included (8 bytes, little-endian). Version 1 files (the same, with "1" and a
// checksum of the payload alone) are still read. The payload is in host byte
// order: a checkpoint resumes on the machine type that wrote it.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>

#include "render/Render.h"

namespace pyrolume {

// What must be equal for a checkpoint to continue a render.
struct CheckpointIdentity {
  std::string backend;     // "cpu" | "vulkan": the payload's layout
  std::string scene;       // the scene file as given (messages only)
  uint64_t scene_hash = 0; // scene_fingerprint() of it
  int width = 0, height = 0;
  uint32_t seed = 0, frame = 0;
  std::string device;      // informational: a GPU checkpoint may resume on another GPU
};

struct Checkpoint {
  CheckpointIdentity identity;
  int spp_target = 0;  // what the interrupted render was asked for (informational)
  AccumulationState state;
};

// OUT.exr → OUT.exr.checkpoint, in the output's folder.
std::filesystem::path checkpoint_path(const std::filesystem::path& output);

// FNV-1a 64 of the scene's JSON in canonical form (parsed and re-serialised:
// whitespace and key order do not matter, every value does), or of its raw
// bytes when it does not parse. Files the scene names (grids, meshes, maps) are
// identified by their paths only.
uint64_t scene_fingerprint(const std::filesystem::path& scene_file);

// Atomic (image/AtomicFile.h): an interrupted write leaves the previous
// checkpoint in place. Errors throw InputError "FILE: REASON".
void write_checkpoint(const std::filesystem::path& file, const CheckpointIdentity& identity, int spp_target,
                      const AccumulationState& state);

// The payload size a backend's layout has for a width×height render, 0 for a
// backend it does not know (backends/Backends.h accumulation_bytes).
using PayloadBytes = std::function<uint64_t(const std::string& backend, int width, int height)>;

// Missing, truncated, corrupt or foreign files throw InputError naming the file
// and the reason; the header's size is checked against payload_bytes and the
// file's before the payload is allocated.
Checkpoint read_checkpoint(const std::filesystem::path& file, const PayloadBytes& payload_bytes);

// Throws InputError "FILE: KEY: REASON" naming the first identity field that
// differs (scene, backend, width, height, seed, frame), or when the checkpoint
// has more samples than spp_target.
void check_resumable(const std::filesystem::path& file, const Checkpoint& saved, const CheckpointIdentity& now,
                     int spp_target);

}  // namespace pyrolume
