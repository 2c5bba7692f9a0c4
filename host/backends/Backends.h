#pragma once
// The backends by name: the one place that knows both render/cpu and
// render/vulkan, so the CLI and tools pick a backend without including either.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>

#include "render/Backend.h"
#include "render/Checkpoint.h"

namespace pyrolume {

// "vulkan" or "cpu"; throws InputError for an unknown name, and NoDeviceError
// (util/Error.h) pointing at --backend cpu when no Vulkan device exists.
std::unique_ptr<Backend> make_backend(const std::string& name, const BackendOptions& options = {});

// `pyrolume devices`: one line per device, "*" and "(default)" on the one a
// render with --device `requested` (-1: automatic) would use.
std::string device_list(int requested);

// The size of a backend's AccumulationState for a width×height render, as
// that backend lays it out; 0 for an unknown backend name.
uint64_t accumulation_bytes(const std::string& backend, int width, int height);

// read_checkpoint (render/Checkpoint.h) with every backend's payload size,
// and its sums checked finite: a NaN or an infinity in them (a forged or
// damaged file whose checksum was recomputed) is an InputError naming the
// file, since resumed it would stay in the image for good.
Checkpoint read_checkpoint(const std::filesystem::path& file);

}  // namespace pyrolume
