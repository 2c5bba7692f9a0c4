#pragma once
// Shared by the volume targets (fuzz_vdb, fuzz_nvdb): `pyrolume info` on the
// input, without and with --values, as a user would run it first.
#include <filesystem>
#include <sstream>
#include <string>

#include "fuzz/FuzzSupport.h"
#include "volume/VdbInfo.h"

namespace pyrolume::fuzz {

inline void run_info_both_ways(const std::filesystem::path& path, const std::string& file) {
  for (bool values : {false, true}) {
    try {
      std::ostringstream out;
      run_info_command(path, values, out);
    } catch (const InputError& e) {
      check_input_error(e, file);
    }
  }
}

}  // namespace pyrolume::fuzz
