#include "volume/NanoVdbValidate.h"

// NanoVDB's own nanovdb/util/GridValidator.h is no help here: it reads the
// root's tiles before it knows the table fits, never looks at the node counts
// or the first-node offsets (what linear walks trust), and its leaf check
// tests the upper node again. Here every field is read only after the bytes
// it sits in were checked, with offsets as integers (no pointer is formed
// from an unchecked one).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/IO.h>

#include "util/Error.h"
#include "util/Math.h"

namespace pyrolume {

namespace {

using nanovdb::Coord;

std::string text(const Coord& c) {
  return "(" + std::to_string(c[0]) + ", " + std::to_string(c[1]) + ", " + std::to_string(c[2]) + ")";
}

const char* const kLevelNames[] = {"leaf", "lower internal", "upper internal"};

// The active voxels the nodes hold: a count (saturating) and their box.
struct ActiveVoxels {
  uint64_t count = 0;
  int64_t lo[3] = {INT64_MAX, INT64_MAX, INT64_MAX}, hi[3] = {INT64_MIN, INT64_MIN, INT64_MIN};

  void add_box(const Coord& o, int64_t dim) {
    const uint64_t n = uint64_t(dim) * uint64_t(dim) * uint64_t(dim);
    count = saturating_add(count, n);
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], int64_t(o[a]));
      hi[a] = std::max(hi[a], int64_t(o[a]) + dim - 1);
    }
  }
  // A leaf's value mask: bit n is voxel (n >> 6, (n >> 3) & 7, n & 7).
  void add_leaf(const Coord& o, const void* mask) {
    uint64_t w[8];
    std::memcpy(w, mask, sizeof w);
    uint64_t any_y = 0, any_z = 0;
    int x0 = 8, x1 = -1;
    for (int x = 0; x < 8; ++x) {
      if (!w[x]) continue;
      count += uint64_t(__builtin_popcountll(w[x]));
      x0 = std::min(x0, x);
      x1 = x;
      for (int y = 0; y < 8; ++y) {
        const uint64_t row = (w[x] >> (8 * y)) & 0xff;
        if (row) any_y |= 1u << y;
        any_z |= row;
      }
    }
    if (x1 < 0) return;
    const int lo_i[3] = {x0, __builtin_ctzll(any_y), __builtin_ctzll(any_z)};
    const int hi_i[3] = {x1, 63 - __builtin_clzll(any_y), 63 - __builtin_clzll(any_z)};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], int64_t(o[a]) + lo_i[a]);
      hi[a] = std::max(hi[a], int64_t(o[a]) + hi_i[a]);
    }
  }
};

class GridChecker {
 public:
  GridChecker(const uint8_t* base, uint64_t size, const std::string& file, const std::string& grid)
      : base_(base), size_(size), file_(file), grid_(grid) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw input_error(file_, "grid \"" + grid_ + "\"", "corrupt NanoVDB grid: " + what);
  }

  template <class T>
  const T& at(uint64_t offset) const {
    return *reinterpret_cast<const T*>(base_ + offset);
  }

  // The byte `offset` away from byte `from` (inside the buffer), with `bytes`
  // after it still inside the buffer, and (when `aligned`) 32-byte aligned.
  uint64_t locate(uint64_t from, int64_t offset, uint64_t bytes, const std::string& what, bool aligned = true) const {
    uint64_t to;
    if (offset >= 0) {
      if (uint64_t(offset) > size_ - from)
        fail(what + " offset " + std::to_string(offset) + " points past the end of the grid's " +
             std::to_string(size_) + " bytes");
      to = from + uint64_t(offset);
    } else {
      const uint64_t back = uint64_t(-(offset + 1)) + 1;  // no overflow at INT64_MIN
      if (back > from) fail(what + " offset " + std::to_string(offset) + " points before the start of the grid");
      to = from - back;
    }
    if (bytes > size_ - to)
      fail(what + " at byte " + std::to_string(to) + " (" + std::to_string(bytes) + " bytes) runs past the end of the grid's " +
           std::to_string(size_) + " bytes");
    if (aligned && to % NANOVDB_DATA_ALIGNMENT != 0)
      fail(what + " at byte " + std::to_string(to) + " is not 32-byte aligned");
    return to;
  }
  uint64_t locate(uint64_t from, uint64_t offset, uint64_t bytes, const std::string& what) const {
    if (offset > uint64_t(INT64_MAX))
      fail(what + " offset " + std::to_string(offset) + " points past the end of the grid's " + std::to_string(size_) +
           " bytes");
    return locate(from, int64_t(offset), bytes, what);
  }

  // The grid header, its name and its blind metadata table; returns where
  // the nodes must end (the blind metadata follows them).
  uint64_t header() const {
    using nanovdb::GridBlindMetaData;
    if (size_ < sizeof(nanovdb::GridData) + sizeof(nanovdb::TreeData<3>))
      fail("its " + std::to_string(size_) + " bytes are shorter than the grid and tree headers");
    const auto& g = at<nanovdb::GridData>(0);
    if (g.mMagic != NANOVDB_MAGIC_NUMBER) fail("bad magic number");
    if (g.mVersion.getMajor() != NANOVDB_MAJOR_VERSION_NUMBER)
      fail("written by NanoVDB " + std::to_string(g.mVersion.getMajor()) + ".x; this build reads " +
           std::to_string(NANOVDB_MAJOR_VERSION_NUMBER) + ".x");
    // GridHandle::grid() steps through a buffer's grids by their sizes: one grid per buffer here.
    if (g.mGridIndex != 0 || g.mGridCount != 1 || g.mGridSize != size_)
      fail("grid index " + std::to_string(g.mGridIndex) + ", count " + std::to_string(g.mGridCount) + " and size " +
           std::to_string(g.mGridSize) + " do not describe the one grid of " + std::to_string(size_) + " bytes read");
    if (uint32_t(g.mGridType) >= uint32_t(nanovdb::GridType::End)) fail("unknown value type " + std::to_string(uint32_t(g.mGridType)));
    if (uint32_t(g.mGridClass) >= uint32_t(nanovdb::GridClass::End))
      fail("unknown grid class " + std::to_string(uint32_t(g.mGridClass)));
    // The affine index-to-world map: finite and invertible as OpenVDB
    // requires of every affine map (|det| >= 3e-15, AffineMap); NanoVDB's
    // grids come from those, and the loader inverts this matrix (a singular
    // one threw out of the loader's former NanoVDB-to-OpenVDB conversion:
    // found by fuzz_nvdb).
    const double* a = g.mMap.mMatD;
    const double det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
                       a[2] * (a[3] * a[7] - a[4] * a[6]);
    bool finite = std::isfinite(det);
    for (int i = 0; i < 3; ++i) finite = finite && std::isfinite(g.mMap.mVecD[i]);
    if (!finite || std::abs(det) < 3e-15)
      fail("its index-to-world map is singular or not finite (determinant " + std::to_string(det) + ")");
    // Its translation within 1e15 voxels of the origin: further out, double
    // arithmetic loses the voxel (2^53 ≈ 9e15), and OpenVDB, recovering the
    // scale as (1 + t) − t, threw "Non-zero scale values required" out of
    // the former NanoVDB-to-OpenVDB conversion (a translation of 4e304: found
    // by fuzz_nvdb).
    double voxel = INFINITY, offset = 0.0;
    for (int c = 0; c < 3; ++c) {
      voxel = std::min(voxel, std::sqrt(a[c] * a[c] + a[3 + c] * a[3 + c] + a[6 + c] * a[6 + c]));
      offset = std::max(offset, std::abs(g.mMap.mVecD[c]));
    }
    if (!(offset <= 1e15 * voxel))
      fail("its index-to-world map puts the grid " +
           (std::ostringstream() << std::setprecision(3) << offset / voxel).str() +
           " voxels from the origin (at most 1e15)");
    uint64_t nodes_end = size_;
    uint64_t table = 0;
    const uint64_t count = g.mBlindMetadataCount;
    if (count > 0) {
      if (count > size_ / sizeof(GridBlindMetaData))
        fail("blind metadata count " + std::to_string(count) + " does not fit in " + std::to_string(size_) + " bytes");
      table = locate(0, g.mBlindMetadataOffset, count * sizeof(GridBlindMetaData), "blind metadata table");
      nodes_end = table;
    }
    if (g.mFlags & uint32_t(nanovdb::GridFlags::HasLongGridName)) {
      // Grid::gridName() reads it from the last blind data.
      if (count == 0) fail("long grid name flag set without blind data");
      const uint64_t meta = table + (count - 1) * sizeof(GridBlindMetaData);
      const auto& m = at<GridBlindMetaData>(meta);
      if (m.mDataClass != nanovdb::GridBlindDataClass::GridName) fail("long grid name flag set without a name in its blind data");
      // Its element count says nothing of its length (OpenToNanoVDB writes
      // 1): the name ends at its terminator, before the grid's end.
      const uint64_t name = locate(meta, m.mByteOffset, 1, "long grid name", /*aligned=*/false);
      if (!std::memchr(base_ + name, 0, size_ - name)) fail("long grid name is not terminated");
    } else if (!std::memchr(g.mGridName, 0, nanovdb::GridData::MaxNameSize)) {
      fail("grid name is not terminated");
    }
    return nodes_end;
  }

  // Only the tree header's root offset: for value types whose nodes
  // pyrolume never walks (it reads no values of them).
  void root_only() const {
    const uint64_t tree = sizeof(nanovdb::GridData);
    const auto& t = at<nanovdb::TreeData<3>>(tree);
    const uint64_t root = locate(tree, t.mNodeOffset[3], 0, "root node");
    if (root < tree + sizeof(nanovdb::TreeData<3>)) fail("root node overlaps the tree header");
  }

 protected:
  const uint8_t* base_;
  uint64_t size_;
  std::string file_, grid_;
};

// The nodes of one NanoGrid<BuildT>.
template <class BuildT>
class TreeChecker : public GridChecker {
  using GridT = nanovdb::NanoGrid<BuildT>;
  using TreeT = typename GridT::TreeType;
  using RootT = typename TreeT::RootType;
  using RootDataT = typename RootT::DataType;
  using Tile = typename RootDataT::Tile;
  using UpperT = typename RootT::ChildNodeType;
  using LowerT = typename UpperT::ChildNodeType;
  using LeafT = typename LowerT::ChildNodeType;
  // FpN leaves vary in size with their bit width: they have no fixed table.
  static constexpr bool kFixedLeaves = LeafT::DataType::FIXED_SIZE;
  static constexpr uint64_t kNodeBytes[3] = {sizeof(LeafT), sizeof(LowerT), sizeof(UpperT)};

 public:
  using GridChecker::GridChecker;

  void check(uint64_t nodes_end, const nanovdb::io::GridMetaData* listed) {
    const uint64_t tree = sizeof(nanovdb::GridData);
    const auto& t = at<nanovdb::TreeData<3>>(tree);
    const uint64_t root = locate(tree, t.mNodeOffset[3], sizeof(RootT), "root node");
    if (root < tree + sizeof(nanovdb::TreeData<3>)) fail("root node overlaps the tree header");
    const auto& r = at<RootDataT>(root);
    const uint64_t tiles = r.mTableSize;
    // Written with statistics off (StatsMode::Disable), a grid has no
    // bounding boxes; the loaders size the volume by the root's.
    if (t.mVoxelCount > 0 && r.mBBox.empty() && !(at<nanovdb::GridData>(0).mFlags & uint32_t(nanovdb::GridFlags::HasBBox)))
      fail("it has no index bounding box (written with statistics disabled); convert it again with bounding boxes on");
    if (root + sizeof(RootT) > nodes_end || tiles > (nodes_end - root - sizeof(RootT)) / sizeof(Tile))
      fail("root table of " + std::to_string(tiles) + " tiles runs past the nodes' end at byte " +
           std::to_string(nodes_end));
    // The node tables in NanoVDB's order after the root's tiles: upper,
    // lower, leaf nodes, each `count` nodes from its first-node offset,
    // before the blind metadata. Linear walks (the sparse loader, both
    // backends) trust exactly these offsets and counts.
    uint64_t prev = root + RootT::memUsage(uint32_t(tiles));
    for (int level = 2; level >= 0; --level) {
      const uint64_t count = t.mNodeCount[level];
      const std::string what = std::string("first ") + kLevelNames[level] + " node";
      count_[level] = count;
      if (count == 0) {
        first_[level] = end_[level] = prev;
        continue;
      }
      if (t.mNodeOffset[level] == 0)
        fail(std::to_string(count) + " " + kLevelNames[level] + " nodes but no first-node offset");
      const uint64_t bytes = kNodeBytes[level];  // the least a node takes (FpN leaves: more)
      const uint64_t first = locate(tree, t.mNodeOffset[level], bytes, what);
      if (first < prev)
        fail(what + " at byte " + std::to_string(first) + " overlaps the nodes before it (they end at byte " +
             std::to_string(prev) + ")");
      if (first > nodes_end || count > (nodes_end - first) / bytes)
        fail(std::to_string(count) + " " + kLevelNames[level] + " nodes of " + std::to_string(bytes) +
             " bytes from byte " + std::to_string(first) + " run past the nodes' end at byte " +
             std::to_string(nodes_end));
      first_[level] = first;
      end_[level] = level == 0 && !kFixedLeaves ? nodes_end : first + count * bytes;
      prev = end_[level];
      if (level > 0 || kFixedLeaves) seen_[level].assign(count, false);
    }

    // The tree: root tiles -> upper -> lower -> leaf nodes.
    std::vector<uint64_t> keys;
    keys.reserve(tiles);
    const uint64_t table = root + sizeof(RootT);
    for (uint64_t i = 0; i < tiles; ++i) {
      const Tile& tile = at<Tile>(table + i * sizeof(Tile));
      // CoordToKey packs x, y, z >> 12 as uint32 into 21 bits each: the top
      // bit of each field and bit 63 are never set.
      constexpr uint64_t kNotAKey = (uint64_t(1) << 20) | (uint64_t(1) << 41) | (uint64_t(1) << 62) | (uint64_t(1) << 63);
      if (tile.key & kNotAKey) fail("root tile " + std::to_string(i) + " has key " + std::to_string(tile.key) + ", not one of a 4096-voxel cube");
      keys.push_back(tile.key);
      const Coord origin = tile.origin();
      if (tile.child == 0) {
        if (tile.state) voxels_.add_box(origin, UpperT::DIM);
        continue;
      }
      const uint64_t upper = child_node(root, tile.child, 2, "root tile " + std::to_string(i) + "'s child");
      internal<UpperT>(upper, origin, 2);
    }
    std::sort(keys.begin(), keys.end());
    if (std::adjacent_find(keys.begin(), keys.end()) != keys.end()) fail("two root tiles have the same key");
    for (int level = 0; level < 3; ++level)
      if (reached_[level] != count_[level])
        fail("the tree reaches " + std::to_string(reached_[level]) + " " + kLevelNames[level] + " nodes; the tree header counts " +
             std::to_string(count_[level]));

    // What the headers say about the active voxels, against what the nodes hold.
    if (t.mVoxelCount != voxels_.count)
      fail("active voxel count " + std::to_string(t.mVoxelCount) + " is not the " + std::to_string(voxels_.count) +
           " its nodes hold");
    const auto& box = r.mBBox;
    if (voxels_.count > 0)
      for (int a = 0; a < 3; ++a)
        if (box.min()[a] != voxels_.lo[a] || box.max()[a] != voxels_.hi[a])
          fail("index bounding box " + text(box.min()) + " - " + text(box.max()) + " is not the box of its active voxels (" +
               std::to_string(voxels_.lo[0]) + ", " + std::to_string(voxels_.lo[1]) + ", " + std::to_string(voxels_.lo[2]) +
               ") - (" + std::to_string(voxels_.hi[0]) + ", " + std::to_string(voxels_.hi[1]) + ", " +
               std::to_string(voxels_.hi[2]) + ")");
    if (listed) {
      bool same = listed->voxelCount == t.mVoxelCount && listed->gridSize == size_;
      for (int level = 0; level < 3; ++level) same = same && listed->nodeCount[level] == t.mNodeCount[level];
      if (voxels_.count > 0) same = same && listed->indexBBox.min() == box.min() && listed->indexBBox.max() == box.max();
      if (!same)
        fail("the file's metadata for it (voxel count, node counts, size or bounding box) does not match the grid");
    }
  }

 private:
  // The node `offset` bytes from byte `from`: one of the `level` table's
  // nodes, reached for the first time.
  uint64_t child_node(uint64_t from, int64_t offset, int level, const std::string& what) {
    const uint64_t node = locate(from, offset, kNodeBytes[level], what);
    if (node < first_[level] || node >= end_[level])
      fail(what + " at byte " + std::to_string(node) + " is outside the " + kLevelNames[level] + " node table");
    if (level > 0 || kFixedLeaves) {
      const uint64_t rel = node - first_[level];
      if (rel % kNodeBytes[level] != 0)
        fail(what + " at byte " + std::to_string(node) + " is not on a " + kLevelNames[level] + " node boundary");
      if (seen_[level][rel / kNodeBytes[level]]) fail(what + " at byte " + std::to_string(node) + " is reached twice");
      seen_[level][rel / kNodeBytes[level]] = true;
    }
    ++reached_[level];
    return node;
  }

  template <class NodeT>
  void internal(uint64_t at_byte, const Coord& expected, int level) {
    const NodeT& node = at<NodeT>(at_byte);
    // origin() is the min of the node's bounding box, which GridStats leaves
    // empty in a node without active values (a leaf whose voxels were all
    // turned off): such a node has no origin to check, and must stay empty
    // (the sparse loader places nodes by origin()).
    const bool unplaced = node.origin() != expected;
    if (unplaced && !node.bbox().empty())
      fail(std::string(kLevelNames[level]) + " node at byte " + std::to_string(at_byte) + " has origin " + text(node.origin()) +
           " where its parent puts " + text(expected));
    const uint64_t active_before = voxels_.count;
    using ChildT = typename NodeT::ChildNodeType;
    const auto* d = node.data();
    for (uint32_t n = 0; n < NodeT::SIZE; ++n) {
      // From the origin the parent gives, not origin() (see above).
      Coord o = NodeT::OffsetToLocalCoord(n);
      o <<= ChildT::TOTAL;
      o += expected;
      if (d->mChildMask.isOn(n)) {
        const uint64_t c = child_node(at_byte, d->mTable[n].child, level - 1,
                                      std::string(kLevelNames[level]) + " node's child " + std::to_string(n));
        if constexpr (std::is_same_v<ChildT, LeafT>) leaf(c, o);
        else internal<ChildT>(c, o, level - 1);
      } else if (d->mValueMask.isOn(n)) {
        voxels_.add_box(o, ChildT::DIM);
      }
    }
    if (unplaced && voxels_.count != active_before)
      fail(std::string(kLevelNames[level]) + " node at byte " + std::to_string(at_byte) +
           " holds active values but has an empty bounding box");
  }

  void leaf(uint64_t at_byte, const Coord& expected) {
    const LeafT& l = at<LeafT>(at_byte);
    if constexpr (!kFixedLeaves) {
      // FpN: 1 << (mFlags >> 5) bits a value, 1 to 16.
      if ((l.data()->mFlags >> 5) > 4) fail("FpN leaf at byte " + std::to_string(at_byte) + " has an invalid bit width");
      if (l.data()->memUsage() > end_[0] - at_byte)
        fail("FpN leaf at byte " + std::to_string(at_byte) + " runs past the nodes' end at byte " + std::to_string(end_[0]));
    }
    if (l.origin() != expected)
      fail("leaf node at byte " + std::to_string(at_byte) + " has origin " + text(l.origin()) + " where its parent puts " +
           text(expected));
    voxels_.add_leaf(l.origin(), &l.data()->mValueMask);
  }

  uint64_t first_[3] = {}, end_[3] = {}, count_[3] = {}, reached_[3] = {};
  std::vector<bool> seen_[3];
  ActiveVoxels voxels_;
};

}  // namespace

void validate_nanovdb_grid(const nanovdb::GridHandle<nanovdb::HostBuffer>& handle, const std::string& file,
                           const std::string& grid, const nanovdb::io::GridMetaData* listed) {
  const auto* base = handle.data();
  if (!base) throw input_error(file, "grid \"" + grid + "\"", "corrupt NanoVDB grid: no data");
  const uint64_t size = handle.size();
  GridChecker g(base, size, file, grid);
  const uint64_t nodes_end = g.header();
  const auto& data = g.at<nanovdb::GridData>(0);
  if (listed) {
    if (listed->gridType != data.mGridType)
      g.fail(std::string("its value type is ") + nanovdb::toStr(data.mGridType) + " where the file lists " +
             nanovdb::toStr(listed->gridType));
    // Grid::gridName() (header() checked it is terminated inside the buffer).
    const char* name = data.mGridName;
    if (data.mFlags & uint32_t(nanovdb::GridFlags::HasLongGridName)) {
      const auto* m = reinterpret_cast<const nanovdb::GridBlindMetaData*>(base + data.mBlindMetadataOffset) +
                      (data.mBlindMetadataCount - 1);
      name = reinterpret_cast<const char*>(m) + m->mByteOffset;
    }
    if (listed->gridName != name) g.fail("its name \"" + std::string(name) + "\" is not the one the file lists");
  }
  switch (data.mGridType) {
    case nanovdb::GridType::Float: return TreeChecker<float>(base, size, file, grid).check(nodes_end, listed);
    case nanovdb::GridType::Double: return TreeChecker<double>(base, size, file, grid).check(nodes_end, listed);
    case nanovdb::GridType::Fp4: return TreeChecker<nanovdb::Fp4>(base, size, file, grid).check(nodes_end, listed);
    case nanovdb::GridType::Fp8: return TreeChecker<nanovdb::Fp8>(base, size, file, grid).check(nodes_end, listed);
    case nanovdb::GridType::Fp16: return TreeChecker<nanovdb::Fp16>(base, size, file, grid).check(nodes_end, listed);
    case nanovdb::GridType::FpN: return TreeChecker<nanovdb::FpN>(base, size, file, grid).check(nodes_end, listed);
    default: return g.root_only();  // not a type whose values pyrolume reads
  }
}

}  // namespace pyrolume
