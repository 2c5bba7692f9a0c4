#include "volume/VdbFile.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <mutex>
#include <array>
#include <climits>
#include <cstdint>
#include <map>
#include <set>
#include <type_traits>
#include <utility>

#include <openvdb/version.h>

#include <nanovdb/util/IO.h>
#include <openvdb/openvdb.h>

#include "util/Error.h"

namespace pyrolume {

VolumeFormat detect_volume_format(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::exists(file, ec)) throw input_error(file.string(), "", "file not found");
  if (std::filesystem::is_directory(file, ec)) throw input_error(file.string(), "", "is a folder, not a VDB file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw input_error(file.string(), "", "cannot open for reading");
  unsigned char magic[8] = {};
  in.read(reinterpret_cast<char*>(magic), sizeof magic);
  // OpenVDB files begin with the int64 OPENVDB_MAGIC 0x56444220 (" BDV" as
  // little-endian bytes); NanoVDB segments begin with the ASCII "NanoVDB".
  if (in.gcount() >= 4 && magic[0] == 0x20 && magic[1] == 0x42 && magic[2] == 0x44 && magic[3] == 0x56)
    return VolumeFormat::OpenVdb;
  if (in.gcount() >= 7 && std::memcmp(magic, "NanoVDB", 7) == 0) return VolumeFormat::NanoVdb;
  throw input_error(file.string(), "", "not an OpenVDB (.vdb) or NanoVDB (.nvdb) file (unrecognised magic bytes)");
}

namespace {

// Bounds-checked little-endian reads of an OpenVDB file's framing, mirroring
// what OpenVDB 10's io::Archive / io::File / MetaMap / GridDescriptor read.
class LayoutReader {
 public:
  LayoutReader(const std::filesystem::path& file) : name_(file.string()), in_(file, std::ios::binary) {
    if (!in_) throw input_error(name_, "", "cannot open for reading");
    std::error_code ec;
    size_ = std::filesystem::file_size(file, ec);
    if (ec) throw input_error(name_, "", "cannot read its size: " + ec.message());
  }

  [[noreturn]] void fail(const std::string& what) const {
    throw input_error(name_, "", "corrupt or truncated OpenVDB file: " + what);
  }
  uint64_t pos() const { return pos_; }
  uint64_t size() const { return size_; }
  uint64_t left() const { return size_ - pos_; }

  void seek(uint64_t p, const char* what) {
    if (p > size_) fail(std::string(what) + " at byte " + std::to_string(p) + " is past the end (" +
                        std::to_string(size_) + " bytes)");
    in_.clear();
    in_.seekg(std::streamoff(p));
    pos_ = p;
  }
  void skip(uint64_t n, const char* what) {
    if (n > left()) fail(std::string(what) + " (" + std::to_string(n) + " bytes) runs past the end of the file");
    seek(pos_ + n, what);
  }
  void bytes(void* out, uint64_t n, const char* what) {
    if (n > left()) fail(std::string(what) + " runs past the end of the file");
    in_.read(static_cast<char*>(out), std::streamsize(n));
    if (!in_) fail(std::string("cannot read ") + what);
    pos_ += n;
  }
  template <class T>
  T value(const char* what) {
    T v{};
    bytes(&v, sizeof v, what);
    return v;
  }
  // io::readString: uint32 length, then the bytes.
  std::string string(const char* what) {
    const uint32_t n = value<uint32_t>(what);
    if (n > left())
      fail(std::string(what) + " claims " + std::to_string(n) + " bytes, more than the " + std::to_string(left()) +
           " left in the file");
    std::string s(n, '\0');
    if (n) bytes(s.data(), n, what);
    return s;
  }

 private:
  std::string name_;
  std::ifstream in_;
  uint64_t size_ = 0, pos_ = 0;
};

// The byte sizes of the metadata types OpenVDB registers whose readValue
// reads a fixed size whatever the stored size says; 0: not one of them.
uint32_t fixed_metadata_size(const std::string& type) {
  static const std::pair<const char*, uint32_t> sizes[] = {
      {"bool", 1},   {"int32", 4},  {"int64", 8},  {"float", 4},  {"double", 8}, {"vec2i", 8},
      {"vec2s", 8},  {"vec2d", 16}, {"vec3i", 12}, {"vec3s", 12}, {"vec3d", 24}, {"vec4i", 16},
      {"vec4s", 16}, {"vec4d", 32}, {"mat4s", 64}, {"mat4d", 128}};
  for (const auto& [name, n] : sizes)
    if (type == name) return n;
  return 0;
}

// io::DelayedLoadMetadata::readValue: uint32 leaf count; the per-leaf mask
// bytes and then (unless the size is ~0) the int64 compressed sizes, each as
// uint32 size + Blosc chunk, or size 0 + the raw array. Both arrays are sized
// by the leaf count and, for Blosc, by the chunk header's uncompressed size.
void check_delayed_load(LayoutReader& r, const std::string& key, uint32_t n) {
  const uint64_t start = r.pos(), end = start + n;
  auto left = [&] { return end - r.pos(); };
  if (n < 8) r.fail(key + " is too short");
  const uint32_t count = r.value<uint32_t>("delayed-load leaf count");
  if (count > r.size()) r.fail(key + ": leaf count " + std::to_string(count) + " exceeds the file's size");
  for (int array = 0; array < 2; ++array) {
    const uint64_t bytes_raw = uint64_t(count) * (array == 0 ? 1 : 8);
    if (left() < 4) r.fail(key + " is truncated");
    const uint32_t bytes = r.value<uint32_t>("delayed-load chunk size");
    if (array == 1 && bytes == UINT32_MAX) break;  // no compressed sizes stored
    if (bytes == 0) {
      if (bytes_raw > left()) r.fail(key + ": raw array runs past the metadata");
      r.skip(bytes_raw, "delayed-load array");
      continue;
    }
    if (bytes < 16 || bytes > left()) r.fail(key + ": Blosc chunk of " + std::to_string(bytes) + " bytes does not fit");
    unsigned char h[16];
    r.bytes(h, 16, "Blosc header");
    uint32_t nbytes, cbytes;
    std::memcpy(&nbytes, h + 4, 4);
    std::memcpy(&cbytes, h + 12, 4);
    // OpenVDB pads small arrays before compressing them (a few hundred bytes at most).
    if (nbytes < bytes_raw || nbytes > bytes_raw + 512 || cbytes > bytes)
      r.fail(key + ": Blosc chunk header does not match the leaf count");
    r.skip(bytes - 16, "Blosc chunk");
  }
  r.seek(start, "metadata value");
}

// MetaMap::readMeta: int32 count, then per entry name, type name, uint32 size
// and the value.
void check_meta_map(LayoutReader& r, const std::string& where) {
  const int32_t count = r.value<int32_t>("metadata count");
  // Each entry holds at least two string lengths and a size: 12 bytes.
  if (count < 0 || uint64_t(count) * 12 > r.left())
    r.fail(where + ": metadata count " + std::to_string(count) + " does not fit in the file");
  for (int32_t i = 0; i < count; ++i) {
    const std::string name = r.string("metadata name");
    const std::string type = r.string("metadata type name");
    const uint32_t n = r.value<uint32_t>("metadata size");
    const std::string key = where + ": metadata \"" + name + "\" (" + type + ")";
    if (n > r.left()) r.fail(key + " claims " + std::to_string(n) + " bytes, past the end of the file");
    const uint32_t fixed = fixed_metadata_size(type);
    if (fixed && n != fixed)
      r.fail(key + " has " + std::to_string(n) + " bytes; the type has " + std::to_string(fixed));
    if (type == "bool" && n == 1) {
      // Read straight into a C++ bool: only 0 and 1 are values.
      const uint64_t at = r.pos();
      if (r.value<unsigned char>("bool metadata") > 1) r.fail(key + " is neither 0 nor 1");
      r.seek(at, "metadata value");
    }
    if (type == "__delayedload" && n > 0) check_delayed_load(r, key, n);
    r.skip(n, "metadata value");
  }
}

}  // namespace

namespace {

// Value types whose trees check_tree walks: bytes of a value, of one stored
// as half (0: never stored as half).
struct TreeValueType {
  const char* tree;
  uint32_t size, half_size;
};
constexpr TreeValueType kTreeTypes[] = {
    {"Tree_float_5_4_3", 4, 2},  {"Tree_double_5_4_3", 8, 2}, {"Tree_int32_5_4_3", 4, 0},
    {"Tree_int64_5_4_3", 8, 0},  {"Tree_vec3s_5_4_3", 12, 6}, {"Tree_vec3d_5_4_3", 24, 6},
    {"Tree_vec3i_5_4_3", 12, 0}};

const TreeValueType* tree_value_type(const std::string& type) {
  for (const auto& t : kTreeTypes)
    if (type == t.tree) return &t;
  return nullptr;
}

constexpr uint32_t kCompressZip = 0x1, kCompressActiveMask = 0x2, kCompressBlosc = 0x4;

uint32_t count_on(const std::vector<unsigned char>& mask) {
  uint32_t n = 0;
  for (unsigned char b : mask) n += uint32_t(__builtin_popcount(b));
  return n;
}

// Grid::readTopology / readBuffers of a Tree<Root<Internal<Internal<Leaf,3>,4>,5>>,
// as OpenVDB 10 reads them from a seekable file (io/Compression.h
// readCompressedValues, tree/RootNode.h, InternalNode.h, LeafNode.h).
class TreeWalker {
 public:
  TreeWalker(LayoutReader& r, const TreeValueType& t, bool half, uint32_t compression, const std::string& key)
      : r_(r), size_(t.size), elem_(half && t.half_size ? t.half_size : t.size), compression_(compression),
        key_(key) {}

  void walk() {
    r_.skip(4, "tree buffer count");  // TreeBase::readTopology
    r_.skip(size_, "background value");
    const uint32_t tiles = r_.value<uint32_t>("root tile count");
    const uint32_t children = r_.value<uint32_t>("root child count");
    if (uint64_t(tiles) * (13 + size_) > r_.left()) fail("root tile count " + std::to_string(tiles) + " does not fit");
    // A child holds at least its origin and two 4096-byte masks.
    if (uint64_t(children) * (12 + 8192) > r_.left())
      fail("root child count " + std::to_string(children) + " does not fit");
    std::set<std::array<int32_t, 3>> origins;
    auto origin = [&](const char* what) {
      std::array<int32_t, 3> o;
      r_.bytes(o.data(), sizeof o, what);
      for (int32_t c : o)
        // Root entries sit on the 4096-voxel lattice; the last voxel of one
        // must not overflow int32 (OpenVDB computes origin + 4095 unchecked).
        if (c % 4096 != 0 || c > INT32_MAX - 4095)
          fail(std::string(what) + " (" + std::to_string(o[0]) + ", " + std::to_string(o[1]) + ", " +
               std::to_string(o[2]) + ") is not on the 4096-voxel lattice");
      // OpenVDB's root table keeps one node per origin and leaks a replaced child.
      if (!origins.insert(o).second) fail(std::string(what) + " repeats an origin");
      return o;
    };
    for (uint32_t n = 0; n < tiles; ++n) {
      origin("root tile origin");
      r_.skip(size_, "root tile value");
      const unsigned char active = r_.value<unsigned char>("root tile active flag");
      if (active > 1) fail("root tile active flag is " + std::to_string(active) + ", not 0 or 1");
    }
    // Buffers are read in the root table's order (sorted by origin), the
    // topology in file order: remember each child's leaves.
    std::map<std::array<int32_t, 3>, std::vector<uint32_t>> leaves;
    for (uint32_t n = 0; n < children; ++n) {
      const auto o = origin("root child origin");
      internal(5, leaves[o]);
    }
    for (const auto& [o, counts] : leaves)
      for (uint32_t active : counts) {
        r_.skip(64, "leaf value mask");
        values(512, active);
      }
  }

 private:
  [[noreturn]] void fail(const std::string& what) const { r_.fail(key_ + ": " + what); }

  // InternalNode<..., log2>: child mask, value mask, the node's values, then
  // the children in mask order; leaves (log2 3) keep only their value mask.
  void internal(int log2, std::vector<uint32_t>& leaf_counts) {
    const uint32_t n = 1u << (3 * log2), mask_bytes = n / 8;
    std::vector<unsigned char> child_mask(mask_bytes), value_mask(mask_bytes);
    r_.bytes(child_mask.data(), mask_bytes, "child mask");
    r_.bytes(value_mask.data(), mask_bytes, "value mask");
    values(n, count_on(value_mask));
    const uint32_t kids = count_on(child_mask);
    if (log2 == 4) {
      if (uint64_t(kids) * 64 > r_.left()) fail("more leaf nodes than fit in the file");
      std::vector<unsigned char> leaf_mask(64);
      for (uint32_t k = 0; k < kids; ++k) {
        r_.bytes(leaf_mask.data(), 64, "leaf value mask");
        leaf_counts.push_back(count_on(leaf_mask));
      }
      return;
    }
    if (uint64_t(kids) * 1024 > r_.left()) fail("more internal nodes than fit in the file");
    for (uint32_t k = 0; k < kids; ++k) internal(4, leaf_counts);
  }

  // io::readCompressedValues for a node of n values, `active` of them on.
  void values(uint32_t n, uint32_t active) {
    const unsigned char meta = r_.value<unsigned char>("node compression flag");
    // NO_MASK_OR_INACTIVE_VALS .. NO_MASK_AND_ALL_VALS
    if (meta > 6) fail("node compression flag " + std::to_string(meta) + " is not one OpenVDB writes");
    if (meta == 2 || meta == 4 || meta == 5) r_.skip(size_, "inactive value");
    if (meta == 5) r_.skip(size_, "second inactive value");
    if (meta == 3 || meta == 4 || meta == 5) r_.skip(n / 8, "selection mask");
    const uint32_t count = (compression_ & kCompressActiveMask) && meta != 6 ? active : n;
    // HalfReader reads nothing at all, not even a chunk size, for no values.
    if (elem_ != size_ && count == 0) return;
    chunk(uint64_t(count) * elem_);
  }

  // io::readData: Blosc or ZIP chunks carry an int64 size (negative: stored
  // uncompressed, that many bytes); without compression just the bytes.
  void chunk(uint64_t bytes) {
    if (!(compression_ & (kCompressBlosc | kCompressZip))) {
      r_.skip(bytes, "node values");
      return;
    }
    const int64_t n = r_.value<int64_t>("compressed chunk size");
    if (n <= 0) {
      if (n == INT64_MIN || uint64_t(-n) != bytes)
        fail("uncompressed chunk of " + std::to_string(n == INT64_MIN ? 0 : -n) + " bytes where " +
             std::to_string(bytes) + " are expected");
      r_.skip(bytes, "node values");
      return;
    }
    if (uint64_t(n) > r_.left()) fail("compressed chunk of " + std::to_string(n) + " bytes runs past the end");
    if (compression_ & kCompressBlosc) {
      // Blosc decompresses by its own header's sizes, not the chunk's.
      unsigned char h[16];
      if (n < 16) fail("Blosc chunk shorter than its header");
      r_.bytes(h, 16, "Blosc header");
      uint32_t nbytes, cbytes;
      std::memcpy(&nbytes, h + 4, 4);
      std::memcpy(&cbytes, h + 12, 4);
      if (nbytes != bytes || cbytes > uint64_t(n) || cbytes < 16)
        fail("Blosc chunk header (" + std::to_string(nbytes) + " bytes from " + std::to_string(cbytes) +
             ") does not match the chunk (" + std::to_string(bytes) + " bytes from " + std::to_string(n) + ")");
      r_.skip(uint64_t(n) - 16, "Blosc chunk");
      return;
    }
    r_.skip(uint64_t(n), "ZIP chunk");
  }

  LayoutReader& r_;
  uint32_t size_, elem_, compression_;
  std::string key_;
};

// Transform::read: the map's type name, then its fixed-size members
// (math/Maps.h); a frustum holds a second map.
void check_map(LayoutReader& r, const std::string& key, int depth = 0) {
  const std::string type = r.string("transform type");
  static const std::pair<const char*, uint32_t> sizes[] = {
      {"AffineMap", 128},          {"UnitaryMap", 128},        {"ScaleMap", 120}, {"UniformScaleMap", 120},
      {"ScaleTranslateMap", 144}, {"UniformScaleTranslateMap", 144}, {"TranslationMap", 24}};
  for (const auto& [name, n] : sizes)
    if (type == name) return r.skip(n, "transform");
  if (type == "NonlinearFrustumMap" && depth == 0) {
    r.skip(48 + 8 + 8, "frustum");
    return check_map(r, key, 1);
  }
  r.fail(key + ": unknown transform type \"" + type + "\"");
}

// Archive::readHeader reads the file's UUID with boost's `operator>>`: 36
// characters, hex digits with dashes at 8, 13, 18 and 23 (8-4-4-4-12). Any
// other character there (a space, a tab) fails the stream, and every later
// read of OpenVDB's then leaves its value unset: a string length taken from
// uninitialised memory asked a fuzzed file for 4 GiB.
void check_uuid(LayoutReader& r) {
  char uuid[36];
  r.bytes(uuid, sizeof uuid, "file UUID");
  for (int i = 0; i < 36; ++i) {
    const bool dash = i == 8 || i == 13 || i == 18 || i == 23;
    if (dash ? uuid[i] != '-' : !std::isxdigit(static_cast<unsigned char>(uuid[i])))
      r.fail("file UUID is not 32 hex digits in the 8-4-4-4-12 form (byte " + std::to_string(i) + ")");
  }
}

// GridDescriptor::stripSuffix, and File::findDescriptor's "name[N]" form.
std::string base_grid_name(const std::string& name) {
  std::string s = name.substr(0, name.find('\x1e'));
  const size_t open = s.rfind('[');
  if (open != std::string::npos && s.size() > open + 2 && s.back() == ']' &&
      s.find_first_not_of("0123456789", open + 1) == s.size() - 1)
    s.erase(open);
  return s;
}

struct Descriptor {
  std::string unique_name, type, parent;
  int64_t grid_pos, block_pos, end_pos;
};

}  // namespace

std::vector<std::string> validate_openvdb_file(const std::filesystem::path& file,
                                               const std::function<bool(const std::string&)>& walk_tree) {
  LayoutReader r(file);
  // Archive::readHeader.
  if (r.value<int64_t>("magic number") != 0x56444220) r.fail("bad magic number");
  const uint32_t version = r.value<uint32_t>("file format version");
  // 222: per-node compression flags (OpenVDB 3.0, 2014). Older layouts are
  // not walked, so not accepted.
  if (version < 222 || version > openvdb::OPENVDB_FILE_VERSION)
    throw input_error(file.string(), "",
                      "OpenVDB file format version " + std::to_string(version) + " is not supported (222 to " +
                          std::to_string(openvdb::OPENVDB_FILE_VERSION) + ")");
  r.skip(8, "library version");
  const char offsets = r.value<char>("grid-offsets flag");
  if (!offsets)
    throw input_error(file.string(), "", "written as a stream without grid offsets; save it with openvdb::io::File");
  check_uuid(r);
  check_meta_map(r, "file");
  // File::readGridDescriptors.
  const int32_t grids = r.value<int32_t>("grid count");
  if (grids < 0 || uint64_t(grids) * 36 > r.left())
    r.fail("grid count " + std::to_string(grids) + " does not fit in the file");
  std::vector<Descriptor> ds;
  for (int32_t g = 0; g < grids; ++g) {
    Descriptor d;
    d.unique_name = r.string("grid name");
    d.type = r.string("grid type");
    d.parent = r.string("instance parent name");
    d.grid_pos = r.value<int64_t>("grid position");
    d.block_pos = r.value<int64_t>("block position");
    d.end_pos = r.value<int64_t>("end position");
    const std::string key = "grid \"" + base_grid_name(d.unique_name) + "\"";
    // The grid's data follows its descriptor; the next descriptor follows the data.
    if (!(d.grid_pos >= 0 && uint64_t(d.grid_pos) >= r.pos() && d.grid_pos <= d.block_pos &&
          d.block_pos <= d.end_pos && uint64_t(d.end_pos) <= r.size()))
      r.fail(key + ": offsets " + std::to_string(d.grid_pos) + ", " + std::to_string(d.block_pos) + ", " +
             std::to_string(d.end_pos) + " are not in order within the file's " + std::to_string(r.size()) +
             " bytes");
    r.seek(uint64_t(d.grid_pos), "grid data");
    r.skip(4, "grid compression flags");
    check_meta_map(r, key);
    check_map(r, key);
    if (r.pos() > uint64_t(d.block_pos)) r.fail(key + ": metadata runs into the tree data");
    ds.push_back(d);
    r.seek(uint64_t(d.end_pos), "next grid descriptor");
  }

  // Trees: each requested grid's, and for an instance its parent's (File
  // reads the parent's tree for it).
  std::vector<std::string> walked;
  std::set<size_t> todo;
  for (size_t i = 0; i < ds.size(); ++i)
    if (walk_tree && walk_tree(base_grid_name(ds[i].unique_name))) todo.insert(i);
  for (size_t i : std::set<size_t>(todo)) {
    if (ds[i].parent.empty()) continue;
    bool found = false;
    for (size_t j = 0; j < ds.size(); ++j)
      if (ds[j].unique_name == ds[i].parent && ds[j].parent.empty()) {
        todo.insert(j);
        found = true;
      }
    if (!found)
      r.fail("grid \"" + base_grid_name(ds[i].unique_name) + "\": instance parent \"" + ds[i].parent + "\" is missing");
  }
  for (size_t i : todo) {
    const Descriptor& d = ds[i];
    const std::string key = "grid \"" + base_grid_name(d.unique_name) + "\"";
    std::string type = d.type;
    const std::string half_suffix = "_HalfFloat";
    const bool half = type.size() > half_suffix.size() &&
                      type.compare(type.size() - half_suffix.size(), half_suffix.size(), half_suffix) == 0;
    if (half) type.erase(type.size() - half_suffix.size());
    const TreeValueType* t = tree_value_type(type);
    if (!t) continue;  // not a type pyrolume reads values of
    if (d.parent.empty()) {
      r.seek(uint64_t(d.grid_pos), "grid data");
      const uint32_t compression = r.value<uint32_t>("grid compression flags");
      check_meta_map(r, key);
      check_map(r, key);
      TreeWalker(r, *t, half, compression, key).walk();
      if (r.pos() > uint64_t(d.end_pos)) r.fail(key + ": tree runs past the grid's end position");
    }
    walked.push_back(base_grid_name(d.unique_name));
  }
  return walked;
}

void validate_nanovdb_file(const std::filesystem::path& file) {
  LayoutReader r(file);
  auto fail = [&](const std::string& what) -> void {
    throw input_error(file.string(), "", "corrupt or truncated NanoVDB file: " + what);
  };
  int segments = 0;
  while (r.left() > 0) {
    // io::Header: magic, version, grid count, codec (16 bytes).
    if (r.left() < 16) fail("trailing bytes after the last segment");
    const uint64_t magic = r.value<uint64_t>("segment magic");
    const uint32_t version = r.value<uint32_t>("segment version");
    const uint16_t grids = r.value<uint16_t>("segment grid count");
    const uint16_t codec = r.value<uint16_t>("segment codec");
    if (magic != NANOVDB_MAGIC_NUMBER) fail("segment " + std::to_string(segments) + " has a bad magic number");
    // nanovdb::Version packs major.minor.patch in 11 + 11 + 10 bits.
    if ((version >> 21) != NANOVDB_MAJOR_VERSION_NUMBER)
      throw input_error(file.string(), "",
                        "NanoVDB version " + std::to_string(version >> 21) + "." +
                            std::to_string((version >> 10) & 2047) + " is not supported (this build reads " +
                            std::to_string(NANOVDB_MAJOR_VERSION_NUMBER) + ".x); re-generate the file");
    if (codec != uint16_t(nanovdb::io::Codec::NONE))
      throw input_error(file.string(), "",
                        "NanoVDB grids compressed with " + std::string(codec == 1 ? "ZIP" : codec == 2 ? "Blosc" : "an unknown codec") +
                            " are not supported by this build; write them uncompressed");
    uint64_t data = 0;
    for (uint16_t g = 0; g < grids; ++g) {
      nanovdb::io::MetaData m;
      r.bytes(&m, sizeof m, "grid metadata");
      if (uint32_t(m.gridType) >= uint32_t(nanovdb::GridType::End) ||
          uint32_t(m.gridClass) >= uint32_t(nanovdb::GridClass::End))
        fail("grid " + std::to_string(g) + " has an unknown grid type or class");
      if (m.nameSize < 1 || m.nameSize > r.left()) fail("grid name size " + std::to_string(m.nameSize) + " does not fit");
      std::string name(m.nameSize, '\0');
      r.bytes(name.data(), m.nameSize, "grid name");
      if (name.back() != '\0') fail("grid name is not terminated");
      name.resize(name.find('\0'));
      // Uncompressed: the grid is stored as its gridSize bytes.
      if (m.fileSize != m.gridSize ||
          m.gridSize < sizeof(nanovdb::GridData) + sizeof(nanovdb::TreeData<3>) + sizeof(nanovdb::RootData<nanovdb::NanoUpper<float>>))
        fail("grid \"" + name + "\" has sizes " + std::to_string(m.gridSize) + " / " + std::to_string(m.fileSize) +
             " that do not describe an uncompressed grid");
      data += m.fileSize;
      if (data > r.left()) fail("grid \"" + name + "\" runs past the end of the file");
    }
    r.skip(data, "grid data");
    ++segments;
  }
  if (segments == 0) fail("no segments");
}

void ensure_openvdb_initialized() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

glm::dmat4 openvdb_index_to_world(const openvdb::math::Transform& xform, const std::string& file,
                                  const std::string& grid) {
  if (!xform.isLinear())
    throw input_error(file, "grid \"" + grid + "\"",
                      "non-linear (" + xform.mapType() + ") transform is not supported; only affine maps are");
  const openvdb::math::Mat4d M = xform.baseMap()->getAffineMap()->getMat4();
  // OpenVDB multiplies row vectors, p_world = p_index * M, so its matrix is the
  // transpose of the column-vector one. GLM indexes [column][row], hence the
  // element-for-element copy G[c][r] = M[c][r] *is* that transpose.
  glm::dmat4 G(1.0);
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) G[c][r] = M[c][r];
  return G;
}

bool is_vector_type_name(const std::string& type) {
  std::string t = type;
  std::transform(t.begin(), t.end(), t.begin(), [](unsigned char ch) { return char(std::tolower(ch)); });
  return t.rfind("vec", 0) == 0 || t == "rgba8";
}

}  // namespace pyrolume
