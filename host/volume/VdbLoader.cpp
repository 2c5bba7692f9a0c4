// VDB -> dense arrays. Conventions (docs/volumes.md):
//  - OpenVDB index space is cell-centred: voxel ijk's value is the field's value
//    at the integer index point ijk (tools::BoxSampler interpolates between those
//    points). The dense texel for ijk therefore has its centre at index ijk.
//  - One dense texture per grid, each with its own index->world map. We do NOT
//    resample temperature onto density's lattice (the seed's way): Blender writes
//    `heat`/`flame` at other voxel sizes and half-voxel offsets, and resampling
//    trilinearly onto another lattice and then interpolating again on the GPU
//    blurs the field (a second low-pass, error O(h^2 |f''|) per resampling) and
//    shifts sharp flame fronts. With one texture per grid the GPU lookup
//    reproduces OpenVDB's BoxSampler on the original grid exactly (up to R16F
//    rounding); the price is one extra world->index transform per lookup.
//  - The dense box is the ACTIVE bounding box plus one voxel of zero padding, so
//    trilinear lookups near the edge blend with the background (0) as BoxSampler
//    does, with no clamp-to-border sampler needed.
#include "volume/VdbLoader.h"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <sstream>
#include <type_traits>

#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "util/Error.h"
#include "util/Math.h"
#include "util/Memory.h"
#include "volume/DenseBuilder.h"
#include "volume/NanoVdbValidate.h"
#include "volume/SparseGrid.h"
#include "volume/VdbFile.h"

namespace pyrolume {

namespace {

using dense_build::DenseBuilder;
using dense_build::empty_grid;
using dense_build::finish_grid;
using dense_build::finish_sparse;
using dense_build::kHostBytesPerTexel;
using dense_build::max_dense_texels;
using dense_build::Role;
using dense_build::role_key;
using dense_build::ValueRules;
using dense_build::within_memory;

struct GridEntry {
  std::string name;
  std::string type;  // OpenVDB valueType() ("float", "vec3s", "int32") or NanoVDB toStr(GridType)
};

bool is_scalar_float_type(const std::string& t) {
  // OpenVDB reads grids saved as half into FloatGrid, so "half" never shows up
  // there; NanoVDB names its quantised float grids Float4/8/16/N.
  static const char* ok[] = {"float", "double", "Half", "Float4", "Float8", "Float16", "FloatN"};
  return std::any_of(std::begin(ok), std::end(ok), [&](const char* s) { return t == s; });
}

std::string list_grids(const std::vector<GridEntry>& entries) {
  if (entries.empty()) return "the file has no grids";
  std::ostringstream s;
  s << "the file has:";
  for (size_t i = 0; i < entries.size(); ++i)
    s << (i ? ", " : " ") << '"' << entries[i].name << "\" (" << entries[i].type << ')';
  return s.str();
}

const GridEntry* find_grid(const std::vector<GridEntry>& entries, const std::string& name) {
  for (const auto& e : entries)
    if (e.name == name) return &e;
  return nullptr;
}

void require_scalar(const GridEntry& e, Role role, const std::string& file) {
  if (is_scalar_float_type(e.type)) return;
  const std::string what = role == Role::Density ? "a density grid" : "a temperature grid";
  if (is_vector_type_name(e.type))
    throw input_error(file, role_key(role, e.name),
                      "is a vector grid (" + e.type + "); " + what + " must be scalar (float, half or double)");
  throw input_error(file, role_key(role, e.name),
                    "is a " + e.type + " grid; " + what + " must be scalar (float, half or double)");
}

// Which grids to read, by the scene's names or the defaults.
struct GridChoice {
  GridEntry density;
  std::optional<GridEntry> temperature;
};

GridChoice choose_grids(const std::vector<GridEntry>& entries, const VolumeOptions& m, bool need_temperature,
                        const std::string& file, std::vector<std::string>& warnings) {
  GridChoice c;
  const std::string dname = m.density_grid.empty() ? kDefaultDensityGrid : m.density_grid;
  const GridEntry* d = find_grid(entries, dname);
  if (!d) throw input_error(file, role_key(Role::Density, dname), "no such grid; " + list_grids(entries));
  require_scalar(*d, Role::Density, file);
  c.density = *d;
  if (!need_temperature) return c;
  if (!m.temperature_grid.empty()) {
    const GridEntry* t = find_grid(entries, m.temperature_grid);
    if (!t)
      throw input_error(file, role_key(Role::Temperature, m.temperature_grid), "no such grid; " + list_grids(entries));
    require_scalar(*t, Role::Temperature, file);
    c.temperature = *t;
    return c;
  }
  for (const char* name : kDefaultTemperatureGrids) {
    if (const GridEntry* t = find_grid(entries, name)) {
      require_scalar(*t, Role::Temperature, file);
      c.temperature = *t;
      return c;
    }
  }
  warnings.push_back(file + ": no temperature grid (looked for \"temperature\", \"heat\", \"flame\"; " +
                     list_grids(entries) + "): the medium does not emit; set temperature_grid to choose one");
  return c;
}

uint64_t max_sparse_leaves = UINT32_MAX;

// ---- OpenVDB ----

template <class GridT>
DenseGrid dense_from_openvdb(const GridT& grid, const VolumeOptions& m, Role role, const std::string& file,
                             std::vector<std::string>& warnings, const DenseLimits& limits) {
  DenseGrid out;
  out.name = grid.getName();
  const glm::dmat4 grid_to_world = openvdb_index_to_world(grid.transform(), file, out.name);
  const openvdb::CoordBBox bbox = grid.evalActiveVoxelBoundingBox();
  if (grid.activeVoxelCount() == 0 || bbox.empty()) return empty_grid(out.name, grid_to_world, m, role, file, warnings);
  const auto& lo = bbox.min();
  const auto& hi = bbox.max();
  DenseBuilder b(out, {lo.x(), lo.y(), lo.z()}, {hi.x(), hi.y(), hi.z()}, m.downsample, role == Role::Density, file,
                 role, limits);
  // ValueOnCIter visits each active voxel once and each active tile once (as a box).
  for (auto it = grid.tree().cbeginValueOn(); it; ++it) {
    if (it.isVoxelValue()) {
      const openvdb::Coord& c = it.getCoord();
      b.add(c.x(), c.y(), c.z(), double(*it));
    } else {
      openvdb::CoordBBox box;
      it.getBoundingBox(box);
      b.add_box({box.min().x(), box.min().y(), box.min().z()}, {box.max().x(), box.max().y(), box.max().z()},
                double(*it));
    }
  }
  return finish_grid(b, out, grid_to_world, m, role, file, warnings);
}

// texture_format "auto" (docs/volumes.md "Sparse grids"): a dense R16F
// texture where it fits this device and host, unless it is large and mostly
// empty; a sparse tree otherwise. Dense lookups are the faster ones on every
// device measured (docs/benchmarks.md), so sparse is for what dense cannot hold
// or would waste: past kSparseFromBytes, when the tree is under half the
// texture (the box is mostly inactive).
constexpr uint64_t kSparseFromBytes = uint64_t(64) << 20;

bool keep_sparse(const VolumeOptions& m, const glm::i64vec3& bbox_dims, uint64_t sparse_bytes, const DenseLimits& limits) {
  if (m.texture_format == TextureFormat::Sparse) return true;
  if (m.texture_format != TextureFormat::Auto || m.downsample > 1) return false;
  const glm::i64vec3 d = bbox_dims + int64_t(2);  // the zero padding
  const uint64_t texels = uint64_t(d.x) * uint64_t(d.y) * uint64_t(d.z);
  const uint64_t dense = 2 * texels;
  const uint64_t room = memory_available_bytes();
  const bool fits = (limits.max_dim == 0 || std::max({d.x, d.y, d.z}) <= int64_t(limits.max_dim)) &&
                    (limits.max_bytes == 0 || dense <= limits.max_bytes) && texels <= max_dense_texels &&
                    (room == 0 || texels * kHostBytesPerTexel <= room);
  return !fits || (dense > kSparseFromBytes && dense > 2 * sparse_bytes);
}

// Host bytes one leaf of a sparse grid takes while sparse_from_openvdb builds
// it: the OpenVDB copy's leaf and its values, then the NanoVDB leaf.
constexpr uint64_t kSparseLeafBytes =
    sizeof(openvdb::FloatTree::LeafNodeType) + 512 * sizeof(float) + sizeof(nanovdb::NanoLeaf<float>);

// Before a sparse tree is built: every active tile becomes leaves of
// voxels, so a few bytes of tiles (one active 4096³ root tile: 2^27 leaves,
// over 500 GiB) can describe more than any host holds. The leaves it would
// build, against what this process can still allocate; past it, one line
// naming the file and grid instead of allocating into std::bad_alloc.
void require_sparse_memory(uint64_t leaf_count, uint64_t tile_voxels, const std::string& file, Role role,
                           const std::string& name) {
  const uint64_t leaves = leaf_count + tile_voxels / 512;
  std::ostringstream what;
  what << "keeping it sparse (" << leaves << " leaves of 8^3 voxels";
  if (tile_voxels) what << ", " << tile_voxels << " voxels of them in active tiles";
  what << ")";
  const std::string hint = "a \"downsample\": k loads it dense with 1/k^3 of the texels";
  if (leaves > max_sparse_leaves)
    throw input_error(file, role_key(role, name),
                      what.str() + " takes more than the " + std::to_string(max_sparse_leaves) + " leaves a sparse grid may have; " + hint);
  require_memory(file, role_key(role, name), what.str(), leaves * kSparseLeafBytes, hint);
}

// The active box of a grid about to be kept sparse, within the index range
// the sparse walk can step through (one voxel of padding each side).
void require_sparse_box(const glm::i64vec3& lo, const glm::i64vec3& hi, const std::string& file, Role role,
                        const std::string& name) {
  const glm::i64vec3 dims = hi - lo + int64_t(3);
  if (dims.x > (1 << 30) || dims.y > (1 << 30) || dims.z > (1 << 30) || lo.x <= INT32_MIN + 1 || lo.y <= INT32_MIN + 1 ||
      lo.z <= INT32_MIN + 1 || hi.x >= INT32_MAX - 1 || hi.y >= INT32_MAX - 1 || hi.z >= INT32_MAX - 1)
    throw input_error(file, role_key(role, name), "active bounding box reaches the end of the index range");
}

// The same values as DenseBuilder stores (NaN/Inf -> 0, negative density -> 0,
// inactive -> 0), kept in a NanoVDB float tree instead of a dense array: only
// the nonzero active voxels are written, into a tree with background 0, and
// active tiles become voxels (the GPU and CPU walk leaves). The source's
// active values go in through voxel() and tile(), in any order (voxels and
// tiles never overlap), into an OpenVDB float tree that OpenToNanoVDB then
// writes out.
class SparseTreeBuilder {
 public:
  explicit SparseTreeBuilder(Role role) : rules_{role == Role::Density} {}

  void voxel(const openvdb::Coord& c, double v) {
    const float f = rules_.apply(v);
    if (f != 0.0f) acc_.setValue(c, f);
  }
  void tile(const openvdb::CoordBBox& box, double v) {
    const float f = rules_.apply(v, box.volume());
    if (f != 0.0f) tree_->tree().fill(box, f, true);
  }

  DenseGrid finish(DenseGrid& out, const glm::i64vec3& lo, const glm::i64vec3& hi, const glm::dmat4& grid_to_world,
                   const VolumeOptions& m, Role role, const std::string& file, std::vector<std::string>& warnings) {
    tree_->tree().voxelizeActiveTiles();
    auto sparse = std::make_shared<SparseGrid>();
    sparse->handle = nanovdb::openToNanoVDB(*tree_);
    tree_.reset();
    return finish_sparse(out, std::move(sparse), lo, hi, rules_, grid_to_world, m, role, file, warnings);
  }

 private:
  openvdb::FloatGrid::Ptr tree_ = openvdb::FloatGrid::create(0.0f);
  openvdb::FloatGrid::Accessor acc_ = tree_->getAccessor();
  ValueRules rules_;
};

template <class GridT>
DenseGrid sparse_from_openvdb(const GridT& grid, const VolumeOptions& m, Role role, const std::string& file,
                              std::vector<std::string>& warnings) {
  DenseGrid out;
  out.name = grid.getName();
  const glm::dmat4 grid_to_world = openvdb_index_to_world(grid.transform(), file, out.name);
  const openvdb::CoordBBox bbox = grid.evalActiveVoxelBoundingBox();
  if (grid.activeVoxelCount() == 0 || bbox.empty()) return empty_grid(out.name, grid_to_world, m, role, file, warnings);
  const glm::i64vec3 lo(bbox.min().x(), bbox.min().y(), bbox.min().z()), hi(bbox.max().x(), bbox.max().y(), bbox.max().z());
  require_sparse_box(lo, hi, file, role, out.name);
  uint64_t tile_voxels = 0;
  auto tiles = grid.tree().cbeginValueOn();
  tiles.setMaxDepth(GridT::TreeType::ValueOnCIter::LEAF_DEPTH - 1);  // tiles only, not voxels
  for (; tiles; ++tiles) tile_voxels = saturating_add(tile_voxels, tiles.getVoxelCount());
  require_sparse_memory(grid.tree().leafCount(), tile_voxels, file, role, out.name);
  SparseTreeBuilder b(role);
  for (auto it = grid.tree().cbeginValueOn(); it; ++it) {
    if (it.isVoxelValue()) {
      b.voxel(it.getCoord(), double(*it));
    } else {
      openvdb::CoordBBox box;
      it.getBoundingBox(box);
      b.tile(box, double(*it));
    }
  }
  return b.finish(out, lo, hi, grid_to_world, m, role, file, warnings);
}

std::vector<GridEntry> openvdb_grid_entries(openvdb::io::File& f) {
  std::vector<GridEntry> entries;
  try {
    const openvdb::GridPtrVecPtr grids = f.readAllGridMetadata();  // keep alive across the loop
    for (const auto& g : *grids) entries.push_back({g->getName(), g->valueType()});
    return entries;
  } catch (const openvdb::Exception&) {
    // A grid type this build has not registered makes readAllGridMetadata fail
    // for the whole file; list names one by one so the rest stays readable.
  }
  entries.clear();
  for (auto it = f.beginName(); it != f.endName(); ++it) {
    std::string type = "unknown type";
    try {
      type = f.readGridMetadata(*it)->valueType();
    } catch (const openvdb::Exception&) {
    }
    entries.push_back({*it, type});
  }
  return entries;
}

VolumeGrids load_openvdb(const VolumeOptions& m, bool need_temperature, const DenseLimits& limits) {
  ensure_openvdb_initialized();
  const std::string file = m.file.string();
  validate_openvdb_file(m.file);  // OpenVDB trusts the lengths and offsets it reads
  VolumeGrids out;
  try {
    openvdb::io::File f(file);
    // No delayed loading: we touch every active voxel at once anyway, and a
    // memory-mapped file would add its pages to the RSS we promise to bound.
    f.open(/*delayLoad=*/false);
    const GridChoice c = choose_grids(openvdb_grid_entries(f), m, need_temperature, file, out.warnings);
    // The trees of the grids about to be read, before OpenVDB allocates by them.
    const std::vector<std::string> walked = validate_openvdb_file(m.file, [&](const std::string& name) {
      return name == c.density.name || (c.temperature && name == c.temperature->name);
    });
    for (const GridEntry* e : {&c.density, c.temperature ? &*c.temperature : nullptr})
      if (e && std::find(walked.begin(), walked.end(), e->name) == walked.end())
        throw input_error(file, "grid \"" + e->name + "\"", "its tree type cannot be checked, so it is not read");
    auto load = [&](const GridEntry& e, Role role) {
      openvdb::GridBase::Ptr g = f.readGrid(e.name);  // only this grid's tree is read
      out.tree_mem_bytes += g->baseTree().memUsage();
      const openvdb::CoordBBox box = g->evalActiveVoxelBoundingBox();
      std::vector<openvdb::Index32> nodes;  // per level, leaves first
      if (auto fg = openvdb::gridConstPtrCast<openvdb::FloatGrid>(g)) nodes = fg->tree().nodeCount();
      else if (auto dg = openvdb::gridConstPtrCast<openvdb::DoubleGrid>(g)) nodes = dg->tree().nodeCount();
      nodes.resize(4, 0);
      const bool sparse = !box.empty() && keep_sparse(m, glm::i64vec3(box.dim().x(), box.dim().y(), box.dim().z()),
                                                      nanovdb_float_bytes(nodes[0], nodes[1], nodes[2]), limits);
      if (auto fg = openvdb::gridConstPtrCast<openvdb::FloatGrid>(g))
        return sparse ? sparse_from_openvdb(*fg, m, role, file, out.warnings)
                      : dense_from_openvdb(*fg, m, role, file, out.warnings, limits);
      if (auto dg = openvdb::gridConstPtrCast<openvdb::DoubleGrid>(g))
        return sparse ? sparse_from_openvdb(*dg, m, role, file, out.warnings)
                      : dense_from_openvdb(*dg, m, role, file, out.warnings, limits);
      throw input_error(file, role_key(role, e.name), "is a " + g->valueType() + " grid; expected float or double");
    };  // the sparse tree is freed here, before the next grid is read
    out.density = within_memory(file, role_key(Role::Density, c.density.name), [&] { return load(c.density, Role::Density); });
    if (c.temperature)
      out.temperature = within_memory(file, role_key(Role::Temperature, c.temperature->name),
                                      [&] { return load(*c.temperature, Role::Temperature); });
    f.close();
  } catch (const openvdb::Exception& e) {
    throw input_error(file, "", std::string("cannot read as OpenVDB: ") + e.what());
  }
  return out;
}

// ---- NanoVDB ----

// f(grid) for h's grid as the NanoGrid of its value type, for the scalar
// float types pyrolume reads (float, double and NanoVDB's quantised floats);
// nothing for the others.
template <class F>
std::optional<DenseGrid> with_scalar_grid(nanovdb::GridHandle<nanovdb::HostBuffer>& h, F&& f) {
  if (auto* g = h.grid<float>()) return f(*g);
  if (auto* g = h.grid<double>()) return f(*g);
  if (auto* g = h.grid<nanovdb::Fp16>()) return f(*g);
  if (auto* g = h.grid<nanovdb::Fp8>()) return f(*g);
  if (auto* g = h.grid<nanovdb::Fp4>()) return f(*g);
  if (auto* g = h.grid<nanovdb::FpN>()) return f(*g);
  return std::nullopt;
}

template <class BuildT>
DenseGrid dense_from_nanovdb(const nanovdb::NanoGrid<BuildT>& grid, const VolumeOptions& m, Role role,
                             const std::string& file, std::vector<std::string>& warnings, const DenseLimits& limits) {
  DenseGrid out;
  out.name = grid.gridName();
  const glm::dmat4 grid_to_world = nanovdb_index_to_world(grid);
  const auto& bbox = grid.indexBBox();  // bbox of the active values
  if (grid.activeVoxelCount() == 0 || bbox.empty()) return empty_grid(out.name, grid_to_world, m, role, file, warnings);
  DenseBuilder b(out, {bbox.min()[0], bbox.min()[1], bbox.min()[2]}, {bbox.max()[0], bbox.max()[1], bbox.max()[2]},
                 m.downsample, role == Role::Density, file, role, limits);
  auto acc = grid.getAccessor();
  // int64 counters: the box may end at INT32_MAX (DenseBuilder bounded its size).
  for (int64_t k = bbox.min()[2]; k <= bbox.max()[2]; ++k)
    for (int64_t j = bbox.min()[1]; j <= bbox.max()[1]; ++j)
      for (int64_t i = bbox.min()[0]; i <= bbox.max()[0]; ++i) {
        const nanovdb::Coord ijk{int32_t(i), int32_t(j), int32_t(k)};
        if (acc.isActive(ijk)) b.add(i, j, k, double(acc.getValue(ijk)));
      }
  return finish_grid(b, out, grid_to_world, m, role, file, warnings);
}

// A NanoVDB float grid kept sparse as it was read: its values turned into
// what DenseBuilder stores (NaN/Inf -> 0, negative density -> 0, inactive
// voxels and tiles -> 0, background 0) in place, so a large tree is never
// copied. Active tiles stay tiles (SparseGrid reads and visits them). Empty
// for an active root tile with a value (a 4096³ box; rare): sparse_from_openvdb
// takes that grid apart.
std::optional<DenseGrid> sparse_in_place(nanovdb::GridHandle<nanovdb::HostBuffer>& h, const VolumeOptions& m, Role role,
                                         const std::string& file, std::vector<std::string>& warnings) {
  nanovdb::NanoGrid<float>* grid = h.grid<float>();
  if (!grid) return std::nullopt;
  auto& tree = grid->tree();
  auto* root = tree.root().data();
  for (uint32_t t = 0; t < root->mTableSize; ++t)
    if (!root->tile(t)->isChild() && root->tile(t)->state && root->tile(t)->value != 0.0f) return std::nullopt;
  for (uint32_t t = 0; t < root->mTableSize; ++t)
    if (!root->tile(t)->isChild()) root->tile(t)->value = 0.0f;
  root->mBackground = 0.0f;
  DenseGrid out;
  out.name = grid->gridName();
  const glm::dmat4 grid_to_world = nanovdb_index_to_world(*grid);
  ValueRules rules{role == Role::Density};
  uint64_t active = 0;
  glm::ivec3 lo(INT32_MAX), hi(INT32_MIN);
  // An active value v covering a cube of `size` voxels from `o`: what is kept.
  auto process = [&](float f, const glm::ivec3& o, int size) {
    const uint64_t voxels = uint64_t(size) * uint64_t(size) * uint64_t(size);
    active += voxels;
    lo = glm::min(lo, o);
    hi = glm::max(hi, o + (size - 1));
    return rules.apply(f, voxels);
  };
  auto tiles = [&](auto* node, uint64_t count) {
    using Node = std::remove_pointer_t<decltype(node)>;
    for (uint64_t i = 0; i < count; ++i, ++node)
      for (uint32_t n = 0; n < Node::SIZE; ++n) {
        if (node->data()->isChild(n)) continue;
        float f = 0.0f;
        if (node->valueMask().isOn(n)) {
          const nanovdb::Coord o = node->offsetToGlobalCoord(n);
          f = process(node->data()->getValue(n), glm::ivec3(o[0], o[1], o[2]), int(Node::ChildNodeType::DIM));
        }
        node->data()->setValue(n, f);
      }
  };
  if (tree.nodeCount(1)) tiles(tree.getFirstNode<1>(), tree.nodeCount(1));
  if (tree.nodeCount(2)) tiles(tree.getFirstNode<2>(), tree.nodeCount(2));
  // NanoVDB's first-node pointer adds the tree's stored offset: taken only
  // where there are leaves (the validator checks the offsets of levels that
  // have nodes; an empty level's may hold anything, and adding it can overflow).
  auto* leaf = tree.nodeCount(0) ? tree.getFirstNode<0>() : nullptr;
  for (uint64_t l = 0; l < tree.nodeCount(0); ++l, ++leaf) {
    const nanovdb::Coord o = leaf->origin();
    for (uint32_t n = 0; n < 512; ++n) {
      float f = 0.0f;
      if (leaf->valueMask().isOn(n))
        f = process(leaf->getValue(n), glm::ivec3(o[0] + int(n >> 6), o[1] + int((n >> 3) & 7), o[2] + int(n & 7)), 1);
      leaf->setValueOnly(n, f);
    }
  }
  if (active == 0) return empty_grid(out.name, grid_to_world, m, role, file, warnings);
  auto sparse = std::make_shared<SparseGrid>();
  sparse->handle = std::move(h);
  return finish_sparse(out, std::move(sparse), glm::i64vec3(lo), glm::i64vec3(hi), rules, grid_to_world, m, role, file,
                       warnings);
}

// voxel(coord, v) for each active voxel of a NanoVDB grid and tile(box, v)
// for each active tile, through the child pointers from the root (FpN leaves
// differ in size, so a level's nodes are not an array). Nodes are placed by
// their origin(), as the validator checked them.
template <class BuildT, class Voxel, class Tile>
void for_each_active_value(const nanovdb::NanoGrid<BuildT>& grid, Voxel&& voxel, Tile&& tile) {
  using Root = typename nanovdb::NanoGrid<BuildT>::TreeType::RootType;
  auto box = [](const nanovdb::Coord& o, int dim) {
    return openvdb::CoordBBox(openvdb::Coord(o[0], o[1], o[2]), openvdb::Coord(o[0] + dim - 1, o[1] + dim - 1, o[2] + dim - 1));
  };
  auto leaf = [&](const auto& node) {
    const nanovdb::Coord o = node.origin();
    for (uint32_t n = 0; n < 512; ++n)
      if (node.valueMask().isOn(n))
        voxel(openvdb::Coord(o[0] + int(n >> 6), o[1] + int((n >> 3) & 7), o[2] + int(n & 7)), double(node.getValue(n)));
  };
  auto internal = [&](const auto& node, auto&& child) {
    using Node = std::remove_cvref_t<decltype(node)>;
    for (uint32_t n = 0; n < Node::SIZE; ++n) {
      if (node.data()->isChild(n)) child(*node.data()->getChild(n));
      else if (node.valueMask().isOn(n))
        tile(box(node.offsetToGlobalCoord(n), int(Node::ChildNodeType::DIM)), double(node.data()->getValue(n)));
    }
  };
  auto lower = [&](const auto& node) { internal(node, leaf); };
  const auto* root = grid.tree().root().data();
  for (uint32_t t = 0; t < root->mTableSize; ++t) {
    const auto* rt = root->tile(t);
    if (rt->isChild()) internal(*root->getChild(rt), lower);
    else if (rt->state) tile(box(rt->origin(), int(Root::ChildNodeType::DIM)), double(rt->value));
  }
}

// A NanoVDB grid kept sparse through an OpenVDB float tree: other value
// types than float, and float grids with an active root tile (which
// sparse_in_place leaves to this). Two walks: the active box, leaves and tile
// voxels first, for the checks before anything is allocated.
template <class BuildT>
DenseGrid sparse_from_nanovdb(const nanovdb::NanoGrid<BuildT>& grid, const VolumeOptions& m, Role role,
                              const std::string& file, std::vector<std::string>& warnings) {
  DenseGrid out;
  out.name = grid.gridName();
  const glm::dmat4 grid_to_world = nanovdb_index_to_world(grid);
  glm::i64vec3 lo(INT64_MAX), hi(INT64_MIN);
  uint64_t voxels = 0, tile_voxels = 0;
  auto extend = [&](const openvdb::Coord& a, const openvdb::Coord& b) {
    lo = glm::min(lo, glm::i64vec3(a.x(), a.y(), a.z()));
    hi = glm::max(hi, glm::i64vec3(b.x(), b.y(), b.z()));
  };
  for_each_active_value(
      grid,
      [&](const openvdb::Coord& c, double) {
        ++voxels;
        extend(c, c);
      },
      [&](const openvdb::CoordBBox& box, double) {
        tile_voxels = saturating_add(tile_voxels, box.volume());
        extend(box.min(), box.max());
      });
  if (voxels == 0 && tile_voxels == 0) return empty_grid(out.name, grid_to_world, m, role, file, warnings);
  require_sparse_box(lo, hi, file, role, out.name);
  require_sparse_memory(grid.tree().nodeCount(0), tile_voxels, file, role, out.name);
  ensure_openvdb_initialized();
  SparseTreeBuilder b(role);
  for_each_active_value(
      grid, [&](const openvdb::Coord& c, double v) { b.voxel(c, v); },
      [&](const openvdb::CoordBBox& box, double v) { b.tile(box, v); });
  return b.finish(out, lo, hi, grid_to_world, m, role, file, warnings);
}

VolumeGrids load_nanovdb(const VolumeOptions& m, bool need_temperature, const DenseLimits& limits) {
  const std::string file = m.file.string();
  VolumeGrids out;
  std::vector<nanovdb::io::GridMetaData> metas;
  validate_nanovdb_file(m.file);  // nanovdb::io allocates by the sizes it reads
  try {
    metas = nanovdb::io::readGridMetaData(file);
  } catch (const std::exception& e) {
    throw input_error(file, "", std::string("cannot read as NanoVDB: ") + e.what());
  }
  std::vector<GridEntry> entries;
  for (const auto& md : metas) entries.push_back({md.gridName, nanovdb::toStr(md.gridType)});
  const GridChoice c = choose_grids(entries, m, need_temperature, file, out.warnings);
  auto load = [&](const GridEntry& e, Role role) {
    const auto listed = std::find_if(metas.begin(), metas.end(), [&](const auto& md) { return md.gridName == e.name; });
    // nanovdb::io allocates the whole grid at once (validate_nanovdb_file
    // checked its size against the file's).
    if (listed != metas.end()) require_memory(file, role_key(role, e.name), "reading it", listed->gridSize);
    nanovdb::GridHandle<nanovdb::HostBuffer> h;
    try {
      h = nanovdb::io::readGrid<nanovdb::HostBuffer>(file, e.name);
    } catch (const std::exception& ex) {
      // Includes files written with the BLOSC/ZIP codecs, which need
      // NANOVDB_USE_BLOSC/ZIP and their libraries at build time.
      throw input_error(file, role_key(role, e.name), std::string("cannot read NanoVDB grid: ") + ex.what());
    }
    if (!h) throw input_error(file, role_key(role, e.name), "cannot read NanoVDB grid");
    // Before anything follows its offsets or walks its node tables.
    validate_nanovdb_grid(h, file, e.name, listed != metas.end() ? &*listed : nullptr);
    out.tree_mem_bytes += h.size();
    const auto& nb = h.gridMetaData()->indexBBox();
    const auto* tree_data = h.gridMetaData();
    bool sparse = false;
    if (!nb.empty()) {
      const glm::i64vec3 dims(int64_t(nb.max()[0]) - nb.min()[0] + 1, int64_t(nb.max()[1]) - nb.min()[1] + 1,
                              int64_t(nb.max()[2]) - nb.min()[2] + 1);
      sparse = keep_sparse(m, dims, nanovdb_float_bytes(tree_data->nodeCount(0), tree_data->nodeCount(1),
                                                        tree_data->nodeCount(2)), limits);
    }
    if (sparse)
      if (std::optional<DenseGrid> kept = sparse_in_place(h, m, role, file, out.warnings)) return std::move(*kept);
    // Dense, or kept sparse through an OpenVDB tree (other value types than
    // float, and active root tiles).
    auto read = [&](const auto& g) {
      return sparse ? sparse_from_nanovdb(g, m, role, file, out.warnings)
                    : dense_from_nanovdb(g, m, role, file, out.warnings, limits);
    };
    if (std::optional<DenseGrid> g = with_scalar_grid(h, read)) return std::move(*g);
    if (sparse) throw input_error(file, role_key(role, e.name), "NanoVDB grid type " + e.type + " cannot be kept sparse");
    throw input_error(file, role_key(role, e.name), "NanoVDB grid type " + e.type + " is not supported");
  };
  out.density = within_memory(file, role_key(Role::Density, c.density.name), [&] { return load(c.density, Role::Density); });
  if (c.temperature)
    out.temperature = within_memory(file, role_key(Role::Temperature, c.temperature->name),
                                    [&] { return load(*c.temperature, Role::Temperature); });
  return out;
}

}  // namespace

void set_max_dense_texels(uint64_t texels) { max_dense_texels = std::min(texels, uint64_t(1) << 32); }
void set_max_sparse_leaves(uint64_t leaves) { max_sparse_leaves = std::min<uint64_t>(leaves, UINT32_MAX); }

VolumeGrids load_volume(const VolumeOptions& m, const DenseLimits& limits) {
  const std::string file = m.file.string();
  if (m.downsample < 1) throw input_error(file, "downsample", "must be >= 1");
  return detect_volume_format(m.file) == VolumeFormat::NanoVdb ? load_nanovdb(m, m.need_temperature, limits)
                                                               : load_openvdb(m, m.need_temperature, limits);
}

}  // namespace pyrolume
