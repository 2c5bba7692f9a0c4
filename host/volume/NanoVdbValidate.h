#pragma once
// The checks a NanoVDB grid buffer passes before anything walks it
// (docs/robustness.md "Forged NanoVDB trees"). NanoVDB trusts every count and
// offset a buffer stores: its accessors follow child offsets, and the sparse
// loader and both backends walk the node tables linearly from the first-node
// offsets for the stored node counts, writing as they go. A forged count or
// offset in a .nvdb read or wrote past the buffer.
#include <string>

#include <nanovdb/util/GridHandle.h>
#include <nanovdb/util/HostBuffer.h>

namespace nanovdb::io {
struct GridMetaData;
}

namespace pyrolume {

// Checks `handle`'s one grid, bounds first (each field is read only once the
// bytes it sits in are known to be inside the buffer):
//  - the grid header: magic, version, size == the buffer, index and count,
//    value type and class, the index-to-world map (finite, invertible), the
//    name (terminated; a long name's blind data inside the buffer), the blind
//    metadata table;
//  - the tree header: the root and the first upper, lower and leaf node
//    offsets with their node counts, as tables that lie inside the buffer in
//    NanoVDB's order (root and its tiles, uppers, lowers, leaves) without
//    overlapping, 32-byte aligned;
//  - the nodes (for the value types pyrolume reads values of: float, double,
//    Fp4/8/16/N): every root tile key on the 4096-voxel lattice and unique,
//    every child offset landing on a node of the next table, each node
//    reached exactly once, at the origin its parent gives it, so the counts
//    match the tree; FpN bit widths valid;
//  - the active voxel count and the index bounding box against the ones the
//    nodes give, and, when `listed` is given, the file's metadata record for
//    the grid (type, node counts, voxel count, bounding box) against the grid.
// Throws InputError "FILE: grid "NAME": corrupt NanoVDB grid: WHY".
void validate_nanovdb_grid(const nanovdb::GridHandle<nanovdb::HostBuffer>& handle, const std::string& file,
                           const std::string& grid, const nanovdb::io::GridMetaData* listed = nullptr);

}  // namespace pyrolume
