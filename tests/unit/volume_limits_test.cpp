// The grid loader checks a grid against the device's 3D texture limits before
// it allocates the dense array (issue 10 "limits"), naming the file and grid
// and the downsample that would fit; by default ("auto") such a grid is kept
// sparse instead.
#include <gtest/gtest.h>

#include "scene/MediumVolume.h"
#include "support/VdbScenes.h"
#include "util/Error.h"
#include "volume/SparseGrid.h"
#include "volume/VdbLoader.h"

namespace pyrolume {
namespace {

std::string load_error(const Medium& m, const DenseLimits& limits) {
  try {
    load_volume(m, false, limits);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(VolumeLimits, GridPastTheDeviceDimensionIsRefusedBeforeAllocating) {
  auto dir = test::temp_dir("vol-limits");
  // 4503 × 5 × 5 texels: past 4096 along x.
  const auto file = test::write_two_voxels_vdb(dir / "wide.vdb", {4500, 2, 2});
  Medium m = test::vdb_medium("wide", file, {1, 1, 1}, {0, 0, 0});
  // By default ("auto") a grid past the device's limits is kept sparse: the
  // same box, two voxels in a tree.
  const VolumeGrids kept = load_volume(m, false, DenseLimits{4096, 0});
  EXPECT_TRUE(kept.density.is_sparse());
  EXPECT_EQ(kept.density.dims, glm::ivec3(4503, 5, 5));
  EXPECT_EQ(kept.density.sparse->active_voxels(), 2u);
  // A dense texture_format asked for is refused, with the downsample that fits.
  m.texture_format = TextureFormat::R16F;
  const std::string err = load_error(m, DenseLimits{4096, 0});
  EXPECT_NE(err.find(file.string() + ": "), std::string::npos) << err;
  EXPECT_NE(err.find("density"), std::string::npos) << err;
  EXPECT_NE(err.find("4503x5x5 texels (with downsample 1) exceed this device's 3D texture limit of 4096 per axis"),
            std::string::npos)
      << err;
  EXPECT_NE(err.find("add \"downsample\": 2"), std::string::npos) << err;
  // The suggestion fits: with downsample 2 the grid loads (2253 × 4 × 4).
  m.downsample = 2;
  VolumeGrids v = load_volume(m, false, DenseLimits{4096, 0});
  EXPECT_EQ(v.density.dims, glm::ivec3(2253, 4, 4));
  std::filesystem::remove_all(dir);
}

TEST(VolumeLimits, GridPastTheAllocationLimitIsRefused) {
  auto dir = test::temp_dir("vol-bytes");
  const auto file = test::write_two_voxels_vdb(dir / "cube.vdb", {199, 199, 199});  // 202³ texels
  Medium m = test::vdb_medium("cube", file, {1, 1, 1}, {0, 0, 0});
  EXPECT_TRUE(load_volume(m, false, DenseLimits{0, uint64_t(1) << 20}).density.is_sparse());  // "auto"
  m.texture_format = TextureFormat::R16F;
  const std::string err = load_error(m, DenseLimits{0, uint64_t(1) << 20});  // 1 MiB
  EXPECT_NE(err.find("202x202x202 texels (with downsample 1) exceed what this device allows in one allocation (1 MiB"),
            std::string::npos)
      << err;
  // (199/3 + 3)³ · 2 B = 69³ · 2 B fits in 1 MiB; (199/2 + 3)³ · 2 B = 102³ · 2 B does not.
  EXPECT_NE(err.find("add \"downsample\": 3"), std::string::npos) << err;
  // No limits: it loads, dense (8 MiB as R16F is under what "auto" keeps sparse).
  const VolumeGrids dense = load_volume(m, false);
  EXPECT_EQ(dense.density.dims, glm::ivec3(202, 202, 202));
  EXPECT_FALSE(dense.density.is_sparse());
  m.texture_format = TextureFormat::Auto;
  EXPECT_FALSE(load_volume(m, false).density.is_sparse());
  std::filesystem::remove_all(dir);
}

// Active tiles are a few bytes of file each, and a sparse grid turns them
// into leaves of voxels: one active 4096³ root tile, or one upper node full
// of active 128³ tiles, is 2^36 voxels, 2^27 leaves (over 500 GiB). Refused
// before anything is allocated, naming the file and grid, whether "auto"
// picks sparse (the dense box cannot fit either) or the scene asks for it;
// a .nvdb's root tile goes the same way (issue 45). Without the check these
// allocated until the memory limit and ended in std::bad_alloc.
TEST(VolumeLimits, ActiveTilesTooLargeToKeepSparseAreRefusedBeforeAllocating) {
  auto dir = test::temp_dir("vol-tiles");
  const auto root = test::write_tiles_vdb(dir / "root.vdb", 3, 1);
  test::write_nanovdb_copy(root, dir / "root.nvdb");
  const auto upper = test::write_tiles_vdb(dir / "upper.vdb", 2, 32);
  for (const std::filesystem::path& file : {root, dir / "root.nvdb", upper})
    for (TextureFormat format : {TextureFormat::Auto, TextureFormat::Sparse}) {
      Medium m = test::vdb_medium("tiles", file, {1, 1, 1}, {0, 0, 0});
      m.texture_format = format;
      const std::string err = load_error(m, DenseLimits{});
      const std::string what = file.filename().string() + " " + to_string(format) + ": ";
      EXPECT_EQ(err.rfind(file.string() + ": density grid \"density\": keeping it sparse (134217728 leaves of 8^3 "
                                          "voxels, 68719476736 voxels of them in active tiles) needs ",
                          0),
                0u)
          << what << err;
      EXPECT_NE(err.find("this process can still allocate"), std::string::npos) << what << err;
      EXPECT_NE(err.find("\"downsample\""), std::string::npos) << what << err;
    }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace pyrolume
