#pragma once
// Errors at the host's edges. InputError is bad user input (exit status 2); its
// message is one line that names the file, the key or grid, and the reason.
#include <stdexcept>
#include <string>

namespace pyrolume {

struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// "FILE: KEY: REASON" — the shape every input error message takes. Line
// breaks (library messages such as NanoVDB's carry "\n\t") become spaces, so
// the message stays one line.
inline InputError input_error(const std::string& file, const std::string& key, const std::string& reason) {
  std::string msg = file;
  if (!key.empty()) msg += ": " + key;
  msg += ": " + reason;
  for (char& c : msg)
    if (c == '\n' || c == '\r' || c == '\t') c = ' ';
  return InputError(msg);
}

// No device to render on (no driver, no GPU): one line that points to another
// backend (exit status 2). The Vulkan backend throws vk::NoDeviceError.
struct NoDeviceError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace pyrolume
