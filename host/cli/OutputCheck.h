#pragma once
// Before anything is rendered, the outputs of one render are checked against
// what it reads and against each other (docs/robustness.md "Outputs"): an
// output that resolves (through symlinks and hard links) to the scene, a file
// the scene names or another output of the same command is refused, so no
// output can destroy an input or a sibling. Each output's location is
// prepared (missing folders made, writability probed, see prepare_output), so
// an error there ends the command with exit 2 before the render and nothing
// written.
#include <filesystem>
#include <string>
#include <vector>

#include "scene/Scene.h"

namespace pyrolume {

// A file and how the command line or the scene names it ("-o", "--stats",
// "media[0].file", "the scene").
struct NamedPath {
  std::string what;
  std::filesystem::path path;
};

// The files a render of this scene reads (at its frame: expand patterns
// first): the scene itself, the environment map, the vdb files, meshes and
// textures.
std::vector<NamedPath> scene_inputs(const Scene& scene);

// Folders made for outputs; the empty ones are removed again when this goes
// out of scope (a command that failed before writing into them leaves none).
class CreatedFolders {
 public:
  CreatedFolders() = default;
  CreatedFolders(const CreatedFolders&) = delete;
  CreatedFolders& operator=(const CreatedFolders&) = delete;
  ~CreatedFolders();
  std::vector<std::filesystem::path> list;  // outermost first
};

// `prepared` outputs get prepare_output (their folders made, recorded in
// `folders`); `other` outputs (a checkpoint, written only on interruption)
// are only compared. Throws InputError "OUTPUT: WHAT: is the same file as ..."
// for an output that is an input or another output.
void check_outputs(const std::vector<NamedPath>& prepared, const std::vector<NamedPath>& other,
                   const std::vector<NamedPath>& inputs, CreatedFolders& folders);

}  // namespace pyrolume
