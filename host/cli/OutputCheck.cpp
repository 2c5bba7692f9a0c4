#include "cli/OutputCheck.h"

#include "image/AtomicFile.h"
#include "util/Error.h"

namespace pyrolume {

namespace fs = std::filesystem;

std::vector<NamedPath> scene_inputs(const Scene& scene) {
  std::vector<NamedPath> in{{"the scene", scene.file}};
  if (scene.environment) in.push_back({"environment.file", scene.environment->file});
  for (size_t i = 0; i < scene.media.size(); ++i)
    if (scene.media[i].type == Medium::Type::Vdb)
      in.push_back({"media[" + std::to_string(i) + "].file", scene.media[i].file});
  for (size_t i = 0; i < scene.shapes.size(); ++i) {
    const Shape& s = scene.shapes[i];
    if (s.type == Shape::Type::Mesh) in.push_back({"shapes[" + std::to_string(i) + "].mesh", s.mesh});
    if (!s.texture.empty())
      in.push_back({"shapes[" + std::to_string(i) + "].material.diffuse.texture", s.texture});
  }
  return in;
}

CreatedFolders::~CreatedFolders() {
  for (auto it = list.rbegin(); it != list.rend(); ++it) {
    std::error_code ec;
    fs::remove(*it, ec);  // only an empty folder goes
  }
}

void check_outputs(const std::vector<NamedPath>& prepared, const std::vector<NamedPath>& other,
                   const std::vector<NamedPath>& inputs, CreatedFolders& folders) {
  std::vector<std::pair<const NamedPath*, FileIdentity>> outs;
  for (const NamedPath& o : prepared) outs.emplace_back(&o, prepare_output(o.path, &folders.list));
  for (const NamedPath& o : other) outs.emplace_back(&o, identify_file(o.path));
  std::vector<FileIdentity> ins;
  for (const NamedPath& i : inputs) ins.push_back(identify_file(i.path));
  for (size_t k = 0; k < outs.size(); ++k) {
    const NamedPath& out = *outs[k].first;
    for (size_t i = 0; i < inputs.size(); ++i)
      if (same_file(outs[k].second, ins[i]))
        throw input_error(out.path.string(), out.what,
                          "is the same file as " + inputs[i].what + " (" + inputs[i].path.string() +
                              "), which this render reads; refusing to overwrite it");
    for (size_t j = 0; j < k; ++j)
      if (same_file(outs[k].second, outs[j].second))
        throw input_error(out.path.string(), out.what,
                          "is the same file as " + outs[j].first->what + " (" + outs[j].first->path.string() +
                              "); each output needs a file of its own");
  }
}

}  // namespace pyrolume
