// Forged NanoVDB files (docs/robustness.md "Forged NanoVDB trees"): a .nvdb
// whose counts, offsets, sizes, bounding box or value type were changed is
// refused before anything walks it, with one line naming the file, the grid
// and the field, by the dense load, the sparse load (which walks the node
// tables linearly and writes into them) and `pyrolume info --values`.
// Without the checks the large forgeries crashed (SIGSEGV) and the small ones
// loaded silently.
#include <gtest/gtest.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <fstream>
#include <functional>
#include <sstream>
#include <vector>

#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "scene/MediumVolume.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "util/Error.h"
#include "volume/NanoVdbValidate.h"
#include "volume/SparseGrid.h"
#include "volume/VdbInfo.h"
#include "volume/VdbLoader.h"

namespace pyrolume {
namespace {

namespace fs = std::filesystem;
using Bytes = std::vector<char>;

// Byte offsets in a NanoVDB 32 grid buffer (NanoVDB.h: GridData, TreeData, RootData).
static_assert(sizeof(nanovdb::GridData) == 672 && sizeof(nanovdb::TreeData<3>) == 64, "NanoVDB 32 layout");
constexpr size_t kGridSize = 32, kGridType = 636, kTree = 672;
constexpr size_t kMapD = 296 + 88;  // GridData::mMap.mMatD[0] (after the float matrices, translation and taper)
constexpr size_t kVecD = kMapD + 2 * 72;  // GridData::mMap.mVecD[0] (after mMatD and mInvMatD)
constexpr size_t kNodeOffset = kTree, kNodeCount = kTree + 32, kVoxelCount = kTree + 56;
constexpr size_t kRootBBox = 0, kRootTableSize = 24;

template <class T>
T get(const Bytes& b, size_t at) {
  T v;
  std::memcpy(&v, b.data() + at, sizeof v);
  return v;
}
template <class T>
void put(Bytes& b, size_t at, T v) {
  std::memcpy(b.data() + at, &v, sizeof v);
}

// "density": voxels in three leaves under two lower nodes (x = 0 and 200),
// and an active 8³ tile of a lower node: every node level, tiles included.
// Returns the .nvdb's bytes.
Bytes small_nvdb(const fs::path& dir) {
  openvdb::initialize();
  auto g = openvdb::FloatGrid::create(0.0f);
  g->setName("density");
  auto acc = g->getAccessor();
  acc.setValue({0, 0, 0}, 0.5f);
  acc.setValue({9, 1, 2}, 1.0f);
  acc.setValue({200, 3, 4}, 2.0f);
  g->tree().addTile(1, openvdb::Coord(16, 0, 0), 1.5f, true);
  openvdb::io::File(((dir / "small.vdb").string())).write({g});
  test::write_nanovdb_copy(dir / "small.vdb", dir / "small.nvdb");
  std::ifstream in(dir / "small.nvdb", std::ios::binary);
  return Bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Where the grid's buffer starts in a one-grid file: the segment header,
// the grid's metadata record and its name.
size_t grid_start(const Bytes& b) {
  const size_t meta = sizeof(nanovdb::io::Header);
  return meta + sizeof(nanovdb::io::MetaData) + get<uint32_t>(b, meta + offsetof(nanovdb::io::MetaData, nameSize));
}

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

fs::path write(const fs::path& p, const Bytes& b) {
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(b.data(), std::streamsize(b.size()));
  return p;
}

// The three readers a .nvdb meets: "" when it was read, else the InputError.
std::string read_error(const fs::path& p, const std::string& reader) {
  try {
    if (reader == "info --values") {
      std::ostringstream out;
      run_info_command(p, /*values=*/true, out);
    } else {
      Medium m = test::vdb_density_medium("forged", p, {1, 1, 1}, {0, 0, 0});
      m.texture_format = reader == "sparse" ? TextureFormat::Sparse : TextureFormat::R32F;
      load_volume(m, false);
    }
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

struct Forgery {
  const char* field;
  std::function<void(Bytes&, size_t grid)> forge;
  const char* reason;  // in the message
};

TEST(NanoVdbValidate, TheUnforgedFileIsReadByEveryReader) {
  const fs::path dir = test::temp_dir("nvdb-valid");
  const fs::path p = write(dir / "ok.nvdb", small_nvdb(dir));
  for (const char* reader : {"dense", "sparse", "info --values"}) EXPECT_EQ(read_error(p, reader), "") << reader;
  Medium m = test::vdb_density_medium("ok", p, {1, 1, 1}, {0, 0, 0});
  m.texture_format = TextureFormat::Sparse;
  const VolumeGrids g = load_volume(m, false);
  ASSERT_TRUE(g.density.is_sparse());
  EXPECT_EQ(g.density.sparse->active_voxels(), 3u + 512u);
  fs::remove_all(dir);
}

// Found by fuzz_nvdb: in a grid without leaves the first-leaf offset means
// nothing and may hold anything, but the sparse loader took the first leaf's
// address from it all the same (a pointer overflow, UBSan's
// pointer-overflow in the sanitized build, though nothing was read there).
// Every reader loads such a grid: here an active 8³ tile of a lower node.
TEST(NanoVdbValidate, ALeaflessGridsFirstLeafOffsetIsNeverFollowed) {
  const fs::path dir = test::temp_dir("nvdb-leafless");
  openvdb::initialize();
  auto g = openvdb::FloatGrid::create(0.0f);
  g->setName("density");
  g->tree().addTile(1, openvdb::Coord(16, 0, 0), 1.5f, true);
  openvdb::io::File(((dir / "leafless.vdb").string())).write({g});
  test::write_nanovdb_copy(dir / "leafless.vdb", dir / "leafless.nvdb");
  std::ifstream in(dir / "leafless.nvdb", std::ios::binary);
  Bytes b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t g0 = grid_start(b);
  ASSERT_EQ(get<uint32_t>(b, g0 + kNodeCount), 0u);
  put<uint64_t>(b, g0 + kNodeOffset, uint64_t(0xfff4000000000000));
  const fs::path p = write(dir / "forged.nvdb", b);
  for (const char* reader : {"dense", "sparse", "info --values"}) EXPECT_EQ(read_error(p, reader), "") << reader;
  Medium m = test::vdb_density_medium("leafless", p, {1, 1, 1}, {0, 0, 0});
  m.texture_format = TextureFormat::Sparse;
  EXPECT_EQ(load_volume(m, false).density.sparse->active_voxels(), 512u);
  fs::remove_all(dir);
}

TEST(NanoVdbValidate, EachForgedFieldIsRefusedByEveryReaderInOneLine) {
  const fs::path dir = test::temp_dir("nvdb-forged");
  const Bytes valid = small_nvdb(dir);
  const size_t g0 = grid_start(valid);
  const size_t root = g0 + kTree + get<uint64_t>(valid, g0 + kNodeOffset + 3 * 8);
  const uint32_t leaves = get<uint32_t>(valid, g0 + kNodeCount);
  ASSERT_EQ(leaves, 3u);
  ASSERT_EQ(get<uint32_t>(valid, g0 + kNodeCount + 4), 2u);  // lower nodes
  ASSERT_EQ(get<uint32_t>(valid, g0 + kNodeCount + 8), 1u);  // upper nodes
  auto add32 = [](size_t field, int64_t d) {
    return [=](Bytes& b, size_t g) { put<uint32_t>(b, g + field, uint32_t(int64_t(get<uint32_t>(b, g + field)) + d)); };
  };
  auto add64 = [](size_t field, int64_t d) {
    return [=](Bytes& b, size_t g) { put<uint64_t>(b, g + field, get<uint64_t>(b, g + field) + uint64_t(d)); };
  };
  const int64_t leaf_bytes = sizeof(nanovdb::NanoLeaf<float>);
  const std::vector<Forgery> forgeries = {
      {"leaf count (large)", add32(kNodeCount, 1000000), "leaf nodes of"},
      {"leaf count (one more)", add32(kNodeCount, 1), "run past the nodes' end"},
      {"leaf count (one fewer)", add32(kNodeCount, -1), "is outside the leaf node table"},
      {"lower node count", add32(kNodeCount + 4, 1), "lower internal nodes of"},
      {"upper node count", add32(kNodeCount + 8, 5000), "upper internal nodes of"},
      {"first-leaf offset (past the end)", add64(kNodeOffset, int64_t(1) << 40), "first leaf node offset"},
      {"first-leaf offset (one leaf back)", add64(kNodeOffset, -leaf_bytes), "overlaps the nodes before it"},
      {"first-leaf offset (one leaf on)", add64(kNodeOffset, leaf_bytes), "run past the nodes' end"},
      {"first-leaf offset (unaligned)", add64(kNodeOffset, 4), "not 32-byte aligned"},
      {"first lower node offset", add64(kNodeOffset + 8, -int64_t(sizeof(nanovdb::NanoUpper<float>))),
       "overlaps the nodes before it"},
      {"root offset", add64(kNodeOffset + 24, int64_t(1) << 33), "root node offset"},
      {"grid size", add64(kGridSize, 32), "do not describe the one grid"},
      {"active voxel count", add64(kVoxelCount, 1), "active voxel count 516 is not the 515 its nodes hold"},
      {"root table size", [&](Bytes& b, size_t) { put<uint32_t>(b, root + kRootTableSize, 100000000); }, "root table of"},
      {"index bounding box", [&](Bytes& b, size_t) { put<int32_t>(b, root + kRootBBox, -1); },
       "is not the box of its active voxels"},
      {"value type", [](Bytes& b, size_t g) { put<uint32_t>(b, g + kGridType, uint32_t(nanovdb::GridType::Double)); },
       "its value type is double where the file lists float"},
      // Found by fuzz_nvdb: nanoToOpenVDB (the sparse path of a root tile
      // and of quantised grids) threw OpenVDB's ArithmeticError out of the loader.
      {"index-to-world map", [](Bytes& b, size_t g) { put<double>(b, g + kMapD, 0.0); },
       "index-to-world map is singular or not finite"},
      // Found by fuzz_nvdb: a translation of 4e304 made OpenVDB's scale
      // (1 + t) − t zero, and nanoToOpenVDB threw past the fuzzer's handler.
      {"index-to-world translation", [](Bytes& b, size_t g) { put<double>(b, g + kVecD, 4.46e304); },
       "voxels from the origin (at most 1e15)"},
      // A node's origin is its bounding box's min, unchecked where the box
      // is empty (a node without active values): this one has some.
      {"lower node bounding box (emptied)",
       [](Bytes& b, size_t g) {
         const size_t lower = g + kTree + get<uint64_t>(b, g + kNodeOffset + 8);
         for (int a = 0; a < 3; ++a) {
           put<int32_t>(b, lower + 4 * a, INT32_MAX);
           put<int32_t>(b, lower + 12 + 4 * a, INT32_MIN);
         }
       },
       "holds active values but has an empty bounding box"},
      {"leaf origin",
       [](Bytes& b, size_t g) {
         const size_t leaf = g + kTree + get<uint64_t>(b, g + kNodeOffset);
         put<int32_t>(b, leaf, get<int32_t>(b, leaf) + 8);
       },
       "where its parent puts"},
  };
  for (const Forgery& f : forgeries) {
    Bytes b = valid;
    f.forge(b, g0);
    ASSERT_NE(b, valid) << f.field;
    const fs::path p = write(dir / "forged.nvdb", b);
    for (const char* reader : {"dense", "sparse", "info --values"}) {
      const std::string err = read_error(p, reader);
      const std::string what = std::string(f.field) + ", " + reader + ": ";
      EXPECT_EQ(err.rfind(p.string() + ": grid \"density\": corrupt NanoVDB grid: ", 0), 0u) << what << err;
      EXPECT_NE(err.find(f.reason), std::string::npos) << what << err;
      EXPECT_EQ(err.find('\n'), std::string::npos) << what << err;
    }
  }
  fs::remove_all(dir);
}

// A grid with what a forgery check can mistake for a forgery: voxels at
// negative coordinates, active tiles of a lower and an upper node and of the
// root (when `large`), an inactive root tile, and leaves whose voxels are all off, one
// beside active voxels (its lower node holds no active value) and one alone
// (its upper node neither): OpenToNanoVDB leaves such nodes an empty
// bounding box, whose min is what NanoVDB's origin() returns.
template <class GridT>
typename GridT::Ptr awkward_grid(const std::string& name, bool large) {
  auto g = GridT::create(0);
  g->setName(name);
  auto acc = g->getAccessor();
  acc.setValue({-5, 3, -700}, 0.5);
  acc.setValue({9, 1, 2}, 1.0);
  acc.setValueOff({3000, 3000, 3000}, 2.0);
  acc.setValueOff({5000, 5000, 5000}, 2.0);
  g->tree().addTile(1, openvdb::Coord(16, 0, 0), 1.5, true);
  if (large) {
    g->tree().addTile(2, openvdb::Coord(-128, 0, 0), 0.25, true);
    g->tree().addTile(3, openvdb::Coord(8192, 0, 0), 1.5, true);
  }
  g->tree().addTile(3, openvdb::Coord(-8192, 0, 0), 1.5, false);
  return g;
}

std::string validate_error(const nanovdb::GridHandle<nanovdb::HostBuffer>& h, const std::string& grid = "density",
                           const nanovdb::io::GridMetaData* listed = nullptr) {
  try {
    validate_nanovdb_grid(h, "valid.nvdb", grid, listed);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Grids as NanoVDB's own converter writes them, in every value type
// pyrolume reads and every statistics mode that writes bounding boxes:
// none is refused. Without statistics there are no bounding boxes (the
// loaders size a volume by the root's): refused in one line saying so.
TEST(NanoVdbValidate, GridsThatNanoVdbWritesAreAccepted) {
  openvdb::initialize();
  using nanovdb::HostBuffer;
  using nanovdb::StatsMode;
  const auto f = awkward_grid<openvdb::FloatGrid>("density", true);
  const auto d = awkward_grid<openvdb::DoubleGrid>("density", true);
  for (StatsMode s : {StatsMode::BBox, StatsMode::MinMax, StatsMode::All}) {
    const std::string what = "stats mode " + std::to_string(int(s)) + ", ";
    EXPECT_EQ(validate_error(nanovdb::openToNanoVDB(*f, s)), "") << what << "float";
    EXPECT_EQ(validate_error(nanovdb::openToNanoVDB(*d, s)), "") << what << "double";
    EXPECT_EQ(validate_error(nanovdb::openToNanoVDB<HostBuffer, openvdb::FloatTree, nanovdb::Fp4>(*f, s)), "") << what << "Fp4";
    EXPECT_EQ(validate_error(nanovdb::openToNanoVDB<HostBuffer, openvdb::FloatTree, nanovdb::Fp8>(*f, s)), "") << what << "Fp8";
    EXPECT_EQ(validate_error(nanovdb::openToNanoVDB<HostBuffer, openvdb::FloatTree, nanovdb::Fp16>(*f, s)), "") << what << "Fp16";
    EXPECT_EQ(validate_error(nanovdb::openToNanoVDB<HostBuffer, openvdb::FloatTree, nanovdb::FpN>(*f, s)), "") << what << "FpN";
  }
  const std::string no_box = validate_error(nanovdb::openToNanoVDB(*f, StatsMode::Disable));
  EXPECT_EQ(no_box.rfind("valid.nvdb: grid \"density\": corrupt NanoVDB grid: it has no index bounding box", 0), 0u) << no_box;

  // One file of several grids, one with a name longer than the grid header
  // holds (NanoVDB keeps it as blind data), one with no active voxel, one
  // quantised: each as read from the file, with the file's record of it,
  // and the file through every reader.
  const fs::path dir = test::temp_dir("nvdb-written");
  const std::string long_name(300, 'n');
  auto empty = openvdb::FloatGrid::create(0.0f);
  empty->setName("empty");
  std::vector<nanovdb::GridHandle<HostBuffer>> handles;
  handles.push_back(nanovdb::openToNanoVDB(*awkward_grid<openvdb::FloatGrid>("density", false)));
  handles.push_back(nanovdb::openToNanoVDB(*awkward_grid<openvdb::FloatGrid>(long_name, false)));
  handles.push_back(nanovdb::openToNanoVDB(*empty));
  handles.push_back(nanovdb::openToNanoVDB<HostBuffer, openvdb::FloatTree, nanovdb::FpN>(
      *awkward_grid<openvdb::FloatGrid>("fpn", false)));
  const fs::path p = dir / "written.nvdb";
  nanovdb::io::writeGrids<HostBuffer, std::vector>(p.string(), handles);
  const auto metas = nanovdb::io::readGridMetaData(p.string());
  ASSERT_EQ(metas.size(), 4u);
  for (const auto& md : metas) {
    const auto h = nanovdb::io::readGrid<HostBuffer>(p.string(), md.gridName);
    EXPECT_EQ(validate_error(h, md.gridName, &md), "") << md.gridName.substr(0, 10);
  }
  for (const char* reader : {"dense", "sparse", "info --values"}) EXPECT_EQ(read_error(p, reader), "") << reader;
  fs::remove_all(dir);
}

// The command line: exit 2, the one line, no image, on both backends (the
// grid is refused while the scene loads, before either renders).
TEST(NanoVdbValidate, TheCommandLineRefusesAForgedLeafCountWithExit2) {
  const fs::path dir = test::temp_dir("nvdb-cli");
  Bytes b = small_nvdb(dir);
  const size_t g0 = grid_start(b);
  put<uint32_t>(b, g0 + kNodeCount, 1000000);
  const fs::path nvdb = write(dir / "forged.nvdb", b);
  test::write_file(dir / "s.json", R"({"film": {"width": 8, "height": 8, "spp": 1},
    "media": [{"type": "vdb", "file": "forged.nvdb", "texture_format": "sparse"}]})");
  const std::string line = nvdb.string() + ": grid \"density\": corrupt NanoVDB grid: ";
  for (const char* backend : {"cpu", "vulkan"}) {
    const fs::path out = dir / (std::string(backend) + ".exr");
    const test::CliResult r =
        test::run_cli("render " + q(dir / "s.json") + " -o " + q(out) + " --backend " + backend);
    EXPECT_EQ(r.status, 2) << backend << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << backend << ": " << r.err;
    EXPECT_NE(r.err.find(line), std::string::npos) << backend << ": " << r.err;
    EXPECT_FALSE(fs::exists(out)) << backend;
  }
  const test::CliResult info = test::run_cli("info --values " + q(nvdb));
  EXPECT_EQ(info.status, 2) << info.err;
  EXPECT_EQ(std::count(info.err.begin(), info.err.end(), '\n'), 1) << info.err;
  EXPECT_NE(info.err.find(line), std::string::npos) << info.err;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pyrolume
