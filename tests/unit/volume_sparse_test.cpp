// Sparse grids (texture_format "sparse", issue 26): the NanoVDB tree holds the
// same values as the dense texture (NaN, negative density and inactive voxels
// turned to 0), its trilinear lookups, majorant cells and line rates are the
// dense grid's, a .nvdb file loads as its .vdb does, the emission light made
// from the trees alone gives every emitting point a pdf > 0, and "auto"
// keeps the small grids dense. Every VDB here is written by the test.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <random>

#include "light/EmissionCdf.h"
#include "render/vulkan/GpuScene.h"
#include "scene/MediumVolume.h"
#include "scene/Scene.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "util/Error.h"
#include "volume/MajorantGrid.h"
#include "volume/SparseGrid.h"
#include "volume/StoredVolume.h"
#include "volume/VdbLoader.h"

namespace pyrolume {
namespace {

namespace fs = std::filesystem;

// Random values on a box, with NaN, Inf, negatives and zeros among them, on a
// lattice whose voxels do not start at a leaf boundary.
fs::path write_noisy_grid(const fs::path& file) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.3f, 2.0f);
  std::vector<float> values(size_t(23 * 17 * 29));
  for (size_t n = 0; n < values.size(); ++n) {
    values[n] = u(rng);
    if (n % 97 == 0) values[n] = std::numeric_limits<float>::quiet_NaN();
    if (n % 89 == 0) values[n] = std::numeric_limits<float>::infinity();
    if (n % 5 == 0) values[n] = 0.0f;
  }
  const test::VoxelBox box{{-5, 3, -13}, {17, 19, 15}};
  auto at = [&, box](int i, int j, int k) {
    return values[(size_t(k - box.lo.z) * 17 + size_t(j - box.lo.y)) * 23 + size_t(i - box.lo.x)];
  };
  return test::write_vdb(file, {test::make_float_grid("density", {0.07, {0.3, -0.2, 0.1}}, box, at),
                                test::make_float_grid("temperature", {0.11, {0.0, 0.05, 0.0}},
                                                      {{-3, 1, -9}, {9, 12, 10}}, at)});
}

Medium noisy_medium(const fs::path& file, TextureFormat format) {
  Medium m = test::vdb_medium("noisy", file, {1.0, 1.0, 1.0}, {0.5, 0.5, 0.5}, 0.0, std::nullopt, 1.0, true);
  m.temperature.scale = 1500.0;
  m.texture_format = format;
  return m;
}

class SparseGridTest : public ::testing::Test {
 protected:
  fs::path dir = test::temp_dir("sparse");
  ~SparseGridTest() override { fs::remove_all(dir); }
};

TEST_F(SparseGridTest, LookupsEqualTheDenseFloatTexture) {
  const fs::path file = write_noisy_grid(dir / "noisy.vdb");
  const StoredVolume dense = load_stored_volume(noisy_medium(file, TextureFormat::R32F));
  const StoredVolume sparse = load_stored_volume(noisy_medium(file, TextureFormat::Sparse));
  ASSERT_FALSE(dense.density.grid.is_sparse());
  ASSERT_TRUE(sparse.density.grid.is_sparse());
  ASSERT_TRUE(sparse.temperature && sparse.temperature->grid.is_sparse());
  EXPECT_EQ(sparse.density.format, TextureFormat::Sparse);
  // The same box, range and warnings (NaN/Inf and negatives counted alike).
  EXPECT_EQ(sparse.density.grid.dims, dense.density.grid.dims);
  EXPECT_EQ(sparse.density.grid.origin, dense.density.grid.origin);
  EXPECT_EQ(sparse.density.grid.min_value, dense.density.grid.min_value);
  EXPECT_EQ(sparse.density.grid.max_value, dense.density.grid.max_value);
  EXPECT_EQ(sparse.density.grid.max_texel(), dense.density.grid.max_texel());
  EXPECT_EQ(sparse.warnings, dense.warnings);
  // Lookups inside, on the padding and outside the box, on both grids.
  std::mt19937 rng(3);
  for (const auto* pair : {&sparse.density, &*sparse.temperature}) {
    const DenseGrid& s = pair->grid;
    const DenseGrid& d = pair == &sparse.density ? dense.density.grid : dense.temperature->grid;
    glm::dvec3 lo, hi;
    d.world_bounds(lo, hi);
    std::uniform_real_distribution<double> x(lo.x - 0.2, hi.x + 0.2), y(lo.y - 0.2, hi.y + 0.2), z(lo.z - 0.2, hi.z + 0.2);
    int nonzero = 0;
    for (int n = 0; n < 4000; ++n) {
      const glm::dvec3 p(x(rng), y(rng), z(rng));
      const double a = s.sample_world(p), b = d.sample_world(p);
      ASSERT_NEAR(a, b, 1e-6 * std::max(1.0, std::abs(b))) << s.name << " at " << p.x << ' ' << p.y << ' ' << p.z;
      nonzero += b != 0.0;
    }
    EXPECT_GT(nonzero, 1000) << "the points must hit the grid";
    // Every texel too (the padding ring included).
    for (int k = 0; k < d.dims.z; ++k)
      for (int j = 0; j < d.dims.y; ++j)
        for (int i = 0; i < d.dims.x; ++i) ASSERT_EQ(s.texel(i, j, k), d.texel(i, j, k)) << i << ' ' << j << ' ' << k;
  }
}

TEST_F(SparseGridTest, MajorantCellsEqualTheDenseOnes) {
  const fs::path file = write_noisy_grid(dir / "noisy.vdb");
  const DenseGrid dense = load_stored_volume(noisy_medium(file, TextureFormat::R32F)).density.grid;
  const DenseGrid sparse = load_stored_volume(noisy_medium(file, TextureFormat::Sparse)).density.grid;
  for (const glm::ivec3 res : {glm::ivec3(1), glm::ivec3(2, 2, 2), glm::ivec3(3, 5, 4), glm::ivec3(25, 19, 31)}) {
    const MajorantGrid a = build_majorant_grid(sparse, res), b = build_majorant_grid(dense, res);
    ASSERT_EQ(a.max_density.size(), b.max_density.size());
    for (size_t c = 0; c < a.max_density.size(); ++c)
      ASSERT_EQ(a.max_density[c], b.max_density[c]) << "cell " << c << " at " << res.x << 'x' << res.y << 'x' << res.z;
  }
  EXPECT_EQ(choose_majorant_resolution(sparse, 2.0, 0.5), choose_majorant_resolution(dense, 2.0, 0.5));
}

TEST_F(SparseGridTest, NanoVdbFileLoadsAsItsOpenVdbSource) {
  const fs::path file = write_noisy_grid(dir / "noisy.vdb");
  test::write_nanovdb_copy(file, dir / "noisy.nvdb");
  const DenseGrid a = load_stored_volume(noisy_medium(file, TextureFormat::Sparse)).density.grid;
  const DenseGrid b = load_stored_volume(noisy_medium(dir / "noisy.nvdb", TextureFormat::Sparse)).density.grid;
  ASSERT_TRUE(b.is_sparse());
  EXPECT_EQ(a.dims, b.dims);
  // The .nvdb is processed in place (its active voxels stay active, those
  // turned to 0 included); the .vdb goes through a tree of the nonzero ones.
  size_t nonzero_a = 0, nonzero_b = 0;
  a.sparse->for_each_nonzero([&](const glm::ivec3&, float) { ++nonzero_a; });
  b.sparse->for_each_nonzero([&](const glm::ivec3&, float) { ++nonzero_b; });
  EXPECT_EQ(nonzero_a, nonzero_b);
  EXPECT_GT(nonzero_a, 5000u);
  for (int k = 0; k < a.dims.z; ++k)
    for (int j = 0; j < a.dims.y; ++j)
      for (int i = 0; i < a.dims.x; ++i) ASSERT_EQ(a.texel(i, j, k), b.texel(i, j, k));
  EXPECT_EQ(a.min_value, b.min_value);
  EXPECT_EQ(a.max_value, b.max_value);
}

// The light of a sparse grid: with room for per-cell arrays, the dense grid's
// exactly; built from the trees alone (build_sparse_blocks, for large boxes),
// a block of weight 0 never holds a point that emits, samples carry their own
// pdf, the pdfs integrate to 1, and most samples fall where it is hot.
TEST_F(SparseGridTest, EmissionLightCoversEveryEmittingPoint) {
  const test::Lattice lat{0.05, {0.0, 0.0, 0.0}};
  const fs::path file = test::write_explosion_shell_vdb(dir / "shell.vdb", lat, 9.0, 14.0, 1.0f, 3000.0f, 600.0f);
  Medium m = test::vdb_medium("shell", file, {1.0, 1.0, 1.0}, {1.0, 1.0, 1.0}, 0.0, std::nullopt, 1.0, true);
  m.temperature.cutoff_k = 1500.0;  // only the inner rim glows,
  m.emission.blackbody = BlackbodyMode::Physical;  // and brighter the hotter
  m.texture_format = TextureFormat::R32F;
  const StoredVolume dense = load_stored_volume(m);
  m.texture_format = TextureFormat::Sparse;
  const StoredVolume v = load_stored_volume(m);
  ASSERT_TRUE(v.density.grid.is_sparse());
  const EmissionCdf cell_light = EmissionCdf::build_light(m, v), dense_light = EmissionCdf::build_light(m, dense);
  const EmissionCdf light = EmissionCdf::build_sparse_blocks(
      v.density.grid, &v.temperature->grid, EmissionParams::from_medium(m), EmissionCdf::light_block(v.density.grid.dims - 1));
  ASSERT_FALSE(light.empty());
  glm::dvec3 lo, hi;
  v.density.grid.world_bounds(lo, hi);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int emitting = 0, dark_blocks = 0;
  double integral = 0.0;
  const int n = 200000;
  for (int s = 0; s < n; ++s) {
    const glm::dvec3 p = lo + (hi - lo) * glm::dvec3(u(rng), u(rng), u(rng));
    ASSERT_EQ(cell_light.pdf(p), dense_light.pdf(p));
    integral += light.pdf(p);
    const double rho = v.density.grid.sample_world(p);
    const double T = v.temperature->grid.sample_world(p) * m.temperature.scale;
    if (!(rho > 0.0 && T > m.temperature.cutoff_k)) continue;
    ++emitting;
    if (!(light.pdf(p) > 0.0)) ++dark_blocks;
  }
  EXPECT_GT(emitting, 1000);
  EXPECT_EQ(dark_blocks, 0) << "emitting points in blocks of weight 0";
  const double volume = (hi.x - lo.x) * (hi.y - lo.y) * (hi.z - lo.z);
  EXPECT_NEAR(integral / n * volume, 1.0, 0.03) << "the pdf must integrate to 1 over the grid";
  for (int s = 0; s < 2000; ++s) {
    const EmissionSample e = light.sample(u(rng), {u(rng), u(rng), u(rng)});
    ASSERT_GT(e.pdf, 0.0);
    EXPECT_NEAR(e.pdf, light.pdf(e.p), 1e-6 * e.pdf);
  }
  // The blocks follow the emission nearly as well as the cells do: most
  // samples fall inside the mid-shell radius, where it is hot (a light blind
  // to the temperature puts about 45 % there).
  auto inner_share = [&](const EmissionCdf& l) {
    int inner = 0;
    for (int s = 0; s < 4000; ++s)
      inner += glm::length(l.sample(u(rng), {u(rng), u(rng), u(rng)}).p) < 11.5 * lat.voxel;
    return inner / 4000.0;
  };
  const double block_share = inner_share(light), cell_share = inner_share(dense_light);
  std::printf("share of light samples inside the mid-shell radius: blocks %.3f, cells %.3f\n", block_share,
              cell_share);
  EXPECT_GT(block_share, 0.6);
  EXPECT_GT(block_share, cell_share - 0.15);
}

TEST_F(SparseGridTest, AutoKeepsSmallGridsDense) {
  const fs::path file = write_noisy_grid(dir / "noisy.vdb");
  const StoredVolume v = load_stored_volume(noisy_medium(file, TextureFormat::Auto));
  EXPECT_FALSE(v.density.grid.is_sparse());
  EXPECT_EQ(v.density.format, TextureFormat::R16F);
  // The shipped fire too.
  Scene s = load_scene(fs::path(PYROLUME_SOURCE_DIR) / "assets/scenes/fire.json");
  EXPECT_EQ(s.media[0].texture_format, TextureFormat::Auto);
  EXPECT_FALSE(load_stored_volume(s.media[0]).density.grid.is_sparse());
}

// A .vdb's 16-bit NanoVDB copy, loaded kept sparse and dense, and the .vdb
// itself loaded dense: the same box on the same lattice.
struct QuantisedLoads {
  DenseGrid sparse, dense, source;
};

QuantisedLoads load_quantised_copy(const fs::path& vdb) {
  const fs::path nvdb = fs::path(vdb).replace_extension(".nvdb");
  test::write_nanovdb_copy(vdb, nvdb, /*fp16=*/true);
  Medium m = test::vdb_medium("q", nvdb, {1.0, 1.0, 1.0}, {0.5, 0.5, 0.5}, 0.0, std::nullopt, 1.0, false);
  m.texture_format = TextureFormat::Sparse;
  QuantisedLoads q{load_stored_volume(m).density.grid, {}, {}};
  m.texture_format = TextureFormat::R32F;
  q.dense = load_stored_volume(m).density.grid;
  m.file = vdb;
  q.source = load_stored_volume(m).density.grid;
  EXPECT_TRUE(q.sparse.is_sparse()) << vdb;
  EXPECT_FALSE(q.dense.is_sparse()) << vdb;
  EXPECT_EQ(q.sparse.dims, q.dense.dims) << vdb;
  EXPECT_EQ(q.sparse.origin, q.dense.origin) << vdb;
  EXPECT_EQ(q.dense.dims, q.source.dims) << vdb;
  return q;
}

// A quantised NanoVDB grid (Float16) kept sparse goes through OpenVDB
// (VdbLoader converts it by its value type): it must hold the values the
// dense load decodes from the same file, texel for texel, and those must be
// the float source's to within 16-bit quantisation.
TEST_F(SparseGridTest, QuantisedNanoVdbKeptSparseHoldsWhatTheDenseLoadDecodes) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 2.0f);
  std::vector<float> values(size_t(23 * 17 * 29));
  for (float& v : values) v = u(rng);
  const test::VoxelBox box{{-5, 3, -13}, {17, 19, 15}};
  auto at = [&, box](int i, int j, int k) {
    return values[(size_t(k - box.lo.z) * 17 + size_t(j - box.lo.y)) * 23 + size_t(i - box.lo.x)];
  };
  const auto [sparse, dense, source] =
      load_quantised_copy(test::write_vdb(dir / "q.vdb", {test::make_float_grid("density", {0.07, {0.3, -0.2, 0.1}}, box, at)}));
  ASSERT_FALSE(HasFailure());
  int differ = 0;
  for (int k = 0; k < dense.dims.z; ++k)
    for (int j = 0; j < dense.dims.y; ++j)
      for (int i = 0; i < dense.dims.x; ++i) {
        ASSERT_EQ(sparse.texel(i, j, k), dense.texel(i, j, k)) << i << ' ' << j << ' ' << k;
        ASSERT_NEAR(dense.texel(i, j, k), source.texel(i, j, k), 2.0 / 65535.0 + 1e-6) << i << ' ' << j << ' ' << k;
        differ += dense.texel(i, j, k) != source.texel(i, j, k);
      }
  EXPECT_GT(differ, 100) << "the file must really be quantised";
}

// A quantised NanoVDB grid with active tiles, kept sparse: the loader walks
// its tree from the root and turns each tile of a lower node (8³) or an upper
// node (128³) into voxels. Texel for texel what the dense load of the same
// file decodes, and what the OpenVDB source loads (its values are exact in
// 16 bits).
TEST_F(SparseGridTest, QuantisedNanoVdbTilesKeptSparseHoldWhatTheDenseLoadDecodes) {
  const std::vector<fs::path> sources = {test::write_reader_paths_vdb(dir / "voxels_and_tile.vdb", test::VdbCompression::None),
                                         test::write_tiles_vdb(dir / "lower.vdb", 1, 2),
                                         test::write_tiles_vdb(dir / "upper.vdb", 2, 1)};
  for (const fs::path& vdb : sources) {
    const auto [sparse, dense, source] = load_quantised_copy(vdb);
    ASSERT_FALSE(HasFailure());
    EXPECT_EQ(sparse.max_value, source.max_value) << vdb;
    double sum = 0.0;
    for (int k = 0; k < dense.dims.z; ++k)
      for (int j = 0; j < dense.dims.y; ++j)
        for (int i = 0; i < dense.dims.x; ++i) {
          ASSERT_EQ(sparse.texel(i, j, k), dense.texel(i, j, k)) << vdb << ' ' << i << ' ' << j << ' ' << k;
          ASSERT_EQ(dense.texel(i, j, k), source.texel(i, j, k)) << vdb << ' ' << i << ' ' << j << ' ' << k;
          sum += sparse.texel(i, j, k);
        }
    EXPECT_GT(sum, 0.0) << vdb;
  }
}

// A live edit re-packs the media headers without the leaf tables (they visit
// every leaf): the sparse buffer's layout, and so every offset the GpuGrids
// hold, must be the one the session built its buffer with.
TEST_F(SparseGridTest, HeadersForALiveEditKeepTheSparseLayoutWithoutItsTables) {
  const fs::path file = write_noisy_grid(dir / "noisy.vdb");
  Scene scene;
  scene.media.push_back(noisy_medium(file, TextureFormat::Sparse));
  std::vector<std::optional<StoredVolume>> volumes;
  volumes.push_back(load_stored_volume(scene.media[0]));
  const GpuScene full = build_gpu_scene(scene, volumes);
  ASSERT_EQ(full.grids.size(), 1u);
  ASSERT_FALSE(full.sparse_tables.empty());
  EXPECT_NE(full.grids[0].density.tree, 0u);
  EXPECT_NE(full.grids[0].temperature.tree, 0u);
  // The majorant cells were chosen once, by the line estimator's pass, and kept.
  ASSERT_EQ(full.line.majorant_res.size(), 1u);
  EXPECT_EQ(full.line.majorant_res[0], majorant_resolution(scene, scene.media[0], volumes[0]->density.grid));
  EXPECT_EQ(glm::ivec3(full.grids[0].majorant_res.x, full.grids[0].majorant_res.y, full.grids[0].majorant_res.z),
            full.line.majorant_res[0]);

  scene.media[0].density_scale *= 2.0;  // the edit
  const GpuScene edit = pack_gpu_media(scene, volumes, /*with_luts=*/false, full.line.line, /*with_tables=*/false);
  EXPECT_TRUE(edit.sparse_tables.empty());
  EXPECT_TRUE(edit.sparse_blocks.empty());
  EXPECT_EQ(edit.sparse_bytes, full.sparse_bytes);
  ASSERT_EQ(edit.grids.size(), 1u);
  const gpu::GpuGrid &a = edit.grids[0], &b = full.grids[0];
  EXPECT_EQ(a.density.tree, b.density.tree);
  EXPECT_EQ(a.density.leaf_table, b.density.leaf_table);
  EXPECT_EQ(a.temperature.tree, b.temperature.tree);
  EXPECT_EQ(a.temperature.leaf_table, b.temperature.leaf_table);
  EXPECT_EQ(std::memcmp(&a.density.leaf_origin, &b.density.leaf_origin, sizeof a.density.leaf_origin), 0);
  EXPECT_EQ(std::memcmp(&a.density.leaf_dims, &b.density.leaf_dims, sizeof a.density.leaf_dims), 0);
  EXPECT_EQ(std::memcmp(&a.temperature.leaf_dims, &b.temperature.leaf_dims, sizeof a.temperature.leaf_dims), 0);
  EXPECT_EQ(a.density_scale, 2.0f * b.density_scale);  // while the edit itself goes through
}

TEST_F(SparseGridTest, SparseWithDownsampleIsRefused) {
  const fs::path scene = dir / "s.json";
  std::ofstream(scene) << R"({"media": [{"type": "vdb", "file": "x.vdb", "texture_format": "sparse", "downsample": 2}]})";
  try {
    load_scene(scene);
    FAIL() << "accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(scene.string()), std::string::npos) << what;
    EXPECT_NE(what.find("downsample"), std::string::npos) << what;
    EXPECT_NE(what.find("sparse"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace pyrolume
