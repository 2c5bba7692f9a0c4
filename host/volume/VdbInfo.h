#pragma once
// `pyrolume info FILE.vdb|FILE.nvdb [--values]`: one block per grid with its
// name, value type, class, voxel size, index->world transform, active voxel
// count, index and world bounding boxes and the range of the active values.
#include <filesystem>
#include <ostream>

namespace pyrolume {

// Without `values`, OpenVDB files are read for metadata only (fast for any
// size): counts and bboxes come from the file_voxel_count / file_bbox_min/max
// stats OpenVDB writes per grid, and the value range is printed only when the
// file stores it. With `values`, every grid is loaded and the numbers are
// computed from its active voxels. Returns the exit status (0). Throws
// InputError for a missing or unreadable file.
int run_info_command(const std::filesystem::path& file, bool values, std::ostream& out);

}  // namespace pyrolume
