#pragma once
// What a VDB/NanoVDB file holds, read from its metadata (fast for any size) or,
// with `values`, from every active voxel: file metadata, and per grid its name,
// value type, class, voxel size, index->world transform, active voxel count,
// bounding boxes and value range. `pyrolume info` prints it; the source
// conventions (SourceConventions.h) and auto-framing read it.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

namespace pyrolume {

// One grid; unset fields are unknown.
struct GridInfo {
  std::string name, type, grid_class;
  bool saved_as_half = false;
  glm::dvec3 voxel_size{0.0};
  glm::dmat4 index_to_world{1.0};
  std::optional<uint64_t> active_voxels;
  std::optional<glm::i64vec3> bbox_min, bbox_max;  // inclusive active-voxel box
  std::optional<double> min_value, max_value;
  std::string range_label = "values";  // "|values|" for vector grids (magnitudes)
  uint64_t nonfinite = 0;
  // The tree's leaves, lower and upper internal nodes (from the tree: NanoVDB
  // always, OpenVDB with `values`): what a sparse grid takes.
  std::optional<glm::u64vec3> nodes;
  std::string note;        // why a field is missing
  std::string unreadable;  // non-empty: the grid could not be read (why)

  bool empty() const { return active_voxels && *active_voxels == 0; }
  // The outer faces of the active voxels (cell-centred: voxel ijk covers
  // ijk ± 0.5) mapped to world space, as an axis-aligned box; none when the
  // grid is empty or its box is unknown.
  std::optional<std::pair<glm::dvec3, glm::dvec3>> world_bbox() const;
};

struct VolumeFileInfo {
  std::string file;
  std::string format_text;  // "OpenVDB, file format 3.1/223" or "NanoVDB"
  std::vector<std::pair<std::string, std::string>> metadata;  // file-level (OpenVDB only), as text
  std::vector<GridInfo> grids;

  const GridInfo* grid(const std::string& name) const;  // null: absent or unreadable
  std::string metadata_value(const std::string& key) const;  // "" when absent
};

// Without `values`, OpenVDB files are read for metadata only: counts and
// bboxes come from the file_voxel_count / file_bbox_min/max stats OpenVDB
// writes per grid, and the value range is known only when the file stores it
// (NanoVDB). With `values`, the grids' trees are read and the numbers computed
// from their active voxels (only `only_grid`'s when that is not empty).
// Throws InputError for a missing or unreadable file.
VolumeFileInfo read_volume_file_info(const std::filesystem::path& file, bool values,
                                     const std::string& only_grid = "");

// A size for `info`'s memory line: B, KiB, MiB or GiB, one decimal
// ("0.0 MiB" hid a grid of a few KiB).
std::string footprint_text(double bytes);

// One block per grid, after a line naming the file, its format and creator,
// and one line per other file metadata entry.
void print_volume_file_info(const VolumeFileInfo& info, std::ostream& out);

// `pyrolume info FILE.vdb|FILE.nvdb [--values]`: the file's grids, the source
// convention detected from it and a scene that would render it. Returns the
// exit status (0). Throws InputError for a missing or unreadable file.
int run_info_command(const std::filesystem::path& file, bool values, std::ostream& out);

}  // namespace pyrolume
