#include "render/vulkan/Spirv.h"

#include <filesystem>
#include <fstream>
#include <spirv-tools/optimizer.hpp>
#include <stdexcept>
#include <system_error>
#include <unordered_map>

namespace pyrolume::vk {

namespace fs = std::filesystem;

std::vector<uint32_t> load_spirv(const std::string& name) {
  const std::string file = name.ends_with(".spv") ? name : name + ".spv";
  std::vector<fs::path> dirs;
  std::error_code ec;
  fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) dirs.push_back(exe.parent_path() / "shaders");
#ifdef PYROLUME_SPIRV_DIR
  dirs.push_back(PYROLUME_SPIRV_DIR);
#endif
  for (const fs::path& dir : dirs) {
    fs::path p = dir / file;
    std::ifstream in(p, std::ios::binary | std::ios::ate);
    if (!in) continue;
    std::streamsize bytes = in.tellg();
    // A SPIR-V module is a whole number of words and starts with the magic number.
    if (bytes <= 0 || bytes % 4 != 0) throw std::runtime_error(p.string() + ": not a SPIR-V module (size)");
    std::vector<uint32_t> words(size_t(bytes) / 4);
    in.seekg(0);
    in.read(reinterpret_cast<char*>(words.data()), bytes);
    if (!in || words[0] != 0x07230203u) throw std::runtime_error(p.string() + ": not a SPIR-V module");
    return words;
  }
  std::string where;
  for (const fs::path& d : dirs) where += (where.empty() ? "" : " or ") + d.string();
  throw std::runtime_error("shader " + file + " not found in " + where + " (was the build complete?)");
}

std::vector<uint32_t> specialize_spirv(const std::vector<uint32_t>& spirv,
                                       const std::vector<std::pair<uint32_t, uint32_t>>& specialization) {
  if (specialization.empty()) return spirv;
  std::unordered_map<uint32_t, std::vector<uint32_t>> values;
  for (auto [id, value] : specialization) values[id] = {value};
  spvtools::Optimizer opt(SPV_ENV_VULKAN_1_2);
  opt.SetMessageConsumer([](spv_message_level_t, const char*, const spv_position_t&, const char*) {});
  opt.RegisterPass(spvtools::CreateSetSpecConstantDefaultValuePass(values))
      .RegisterPass(spvtools::CreateFreezeSpecConstantValuePass())
      .RegisterPass(spvtools::CreateFoldSpecConstantOpAndCompositePass())
      .RegisterPass(spvtools::CreateDeadBranchElimPass())
      .RegisterPass(spvtools::CreateAggressiveDCEPass())
      .RegisterPass(spvtools::CreateEliminateDeadFunctionsPass());
  // No validation here: spirv-val checked each module when the build wrote it
  // (CMakeLists.txt), and validating the megakernel again took about half of
  // this function's time on every pipeline.
  spvtools::OptimizerOptions options;
  options.set_run_validator(false);
  std::vector<uint32_t> out;
  if (!opt.Run(spirv.data(), spirv.size(), &out, options) || out.empty()) return spirv;
  return out;
}

}  // namespace pyrolume::vk
