// The real exports in the shared data folder (their publishers list what each
// holds): `info` must print those facts, and load_volume must read each file
// with the default grid names. Read in place, never copied into the project.
#include <gtest/gtest.h>

#include <map>
#include <random>
#include <regex>
#include <sstream>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>

#include "scene/MediumVolume.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "util/Error.h"
#include "volume/VdbInfo.h"
#include "volume/VdbLoader.h"

namespace pyrolume {
namespace {

namespace fs = std::filesystem;

class RealVdb : public ::testing::Test {
 protected:
  fs::path dir;
  void SetUp() override {
    dir = test::real_vdb_dir();
    if (dir.empty()) GTEST_SKIP() << test::kRealVdbAbsent;
  }
  fs::path file(const std::string& name) {
    fs::path p = dir / name;
    if (!fs::exists(p)) ADD_FAILURE() << p << " is missing from the shared data folder";
    return p;
  }
};

// `info` output, one block per grid, keyed by grid name.
std::map<std::string, std::string> info_blocks(const fs::path& p, bool values) {
  std::ostringstream out;
  EXPECT_EQ(run_info_command(p, values, out), 0);
  std::map<std::string, std::string> blocks;
  const std::string s = out.str();
  size_t at = s.find("\ngrid \"");
  while (at != std::string::npos) {
    const size_t name_begin = at + 7, name_end = s.find("\"\n", name_begin);
    const size_t next = s.find("\ngrid \"", name_end);
    blocks[s.substr(name_begin, name_end - name_begin)] = s.substr(name_end + 2, next - name_end - 2);
    at = next;
  }
  return blocks;
}

// "values: [lo, hi]" of one block.
std::pair<double, double> value_range(const std::string& block) {
  std::smatch m;
  const std::regex re(R"(values: \[([^,]+), ([^\]]+)\])");
  if (!std::regex_search(block, m, re)) {
    ADD_FAILURE() << "no value range in:\n" << block;
    return {0, 0};
  }
  return {std::stod(m[1]), std::stod(m[2])};
}

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The dense texture reproduces OpenVDB's own trilinear BoxSampler on the file's grid.
void expect_matches_box_sampler(const fs::path& p, const DenseGrid& d) {
  openvdb::initialize();
  openvdb::io::File f(p.string());
  f.open(false);
  auto g = openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid(d.name));
  ASSERT_TRUE(g);
  auto acc = g->getConstAccessor();
  const openvdb::CoordBBox b = g->evalActiveVoxelBoundingBox();
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(-0.1, 1.1);
  for (int n = 0; n < 20000; ++n) {
    const openvdb::Vec3d idx(b.min().x() + u(rng) * b.dim().x(), b.min().y() + u(rng) * b.dim().y(),
                             b.min().z() + u(rng) * b.dim().z());
    const double ref = openvdb::tools::BoxSampler::sample(acc, idx);
    const openvdb::Vec3d w = g->indexToWorld(idx);
    ASSERT_NEAR(d.sample_world({w.x(), w.y(), w.z()}), ref, 1e-6 * std::max(1.0, std::abs(ref)))
        << p.filename() << " grid " << d.name;
  }
}

TEST_F(RealVdb, HoudiniSmokeInfo) {
  const fs::path p = file("openvdb_smoke1_houdini.vdb");
  auto meta = info_blocks(p, false);
  ASSERT_EQ(meta.size(), 1u);
  const std::string& d = meta["density"];
  EXPECT_TRUE(has(d, "type: float (saved as half), class: fog volume")) << d;
  EXPECT_TRUE(has(d, "voxel size: (0.47619 0.47619 0.47619)")) << d;
  EXPECT_TRUE(has(d, "translation (-34.0476 -13.0952 -26.4286)")) << d;
  EXPECT_TRUE(has(d, "active voxels: 1049275")) << d;
  EXPECT_TRUE(has(d, "index bbox: [1 2 1]-[111 223 112] (111 x 222 x 112)")) << d;
  EXPECT_TRUE(has(d, "world bbox: [-33.8095 -12.381 -26.1905]-[19.0476 93.3333 27.1429]")) << d;
  auto vals = info_blocks(p, true);
  auto [lo, hi] = value_range(vals["density"]);
  EXPECT_NEAR(lo, 1.0e-05, 1e-7);
  EXPECT_NEAR(hi, 5.7148, 1e-4);
}

TEST_F(RealVdb, HoudiniSmokeLoadsDensityOnly) {
  const fs::path p = file("openvdb_smoke1_houdini.vdb");
  Medium m = test::vdb_file_medium(p);
  const VolumeGrids v = load_volume(m, true);
  EXPECT_FALSE(v.temperature);  // no temperature, heat or flame grid
  ASSERT_EQ(v.warnings.size(), 1u);
  EXPECT_TRUE(has(v.warnings[0], "no temperature grid")) << v.warnings[0];
  EXPECT_EQ(v.density.origin, glm::ivec3(0, 1, 0));
  EXPECT_EQ(v.density.dims, glm::ivec3(113, 224, 114));
  EXPECT_NEAR(v.density.min_value, 1.0e-05, 1e-7);
  EXPECT_NEAR(v.density.max_value, 5.7148, 1e-4);
  size_t nonzero = 0;
  for (float x : v.density.values) nonzero += x != 0.0f;
  EXPECT_EQ(nonzero, 1049275u);  // every active voxel is > 0 (min 1e-5), the rest is background
  expect_matches_box_sampler(p, v.density);
}

TEST_F(RealVdb, Blender279FireInfo) {
  const fs::path p = file("blender279_fire_frame075.vdb");
  auto meta = info_blocks(p, false);
  for (const char* name : {"density", "flame", "fuel", "heat", "heat old", "obstacles", "react", "shadow", "velocity"})
    EXPECT_EQ(meta.count(name), 1u) << name;
  EXPECT_EQ(meta.size(), 9u);
  EXPECT_TRUE(has(meta["density"], "voxel size: (1.73238 1.7226 1.72004)")) << meta["density"];
  EXPECT_TRUE(has(meta["density"], "active voxels: 83915")) << meta["density"];
  EXPECT_TRUE(has(meta["density"], "index bbox: [1 1 2]-[20 66 94] (20 x 66 x 93)")) << meta["density"];
  EXPECT_TRUE(has(meta["density"], "world bbox: [-9.80936 -52.2804 -3.97115]-[24.8381 61.411 155.992]"));
  EXPECT_TRUE(has(meta["flame"], "index bbox: [2 6 2]-[19 62 42] (18 x 57 x 41)")) << meta["flame"];
  EXPECT_TRUE(has(meta["obstacles"], "type: int32")) << meta["obstacles"];
  EXPECT_TRUE(has(meta["obstacles"], "active voxels: 0")) << meta["obstacles"];
  EXPECT_TRUE(has(meta["velocity"], "type: vec3s, class: staggered")) << meta["velocity"];
  auto vals = info_blocks(p, true);
  const std::map<std::string, std::pair<double, double>> want = {
      {"density", {0.0010001, 0.193144}}, {"flame", {0.0013287, 0.959915}}, {"fuel", {0.0010107, 0.912156}},
      {"heat", {0.0010809, 1.56721}},     {"heat old", {0.0010939, 1.57446}}, {"react", {0.0010096, 0.921437}}};
  for (const auto& [name, range] : want) {
    auto [lo, hi] = value_range(vals[name]);
    EXPECT_NEAR(lo, range.first, 1e-6) << name;
    EXPECT_NEAR(hi, range.second, 1e-5) << name;
  }
  EXPECT_TRUE(has(vals["heat"], "active voxels: 83904")) << vals["heat"];
}

TEST_F(RealVdb, Blender279FireLoadsDensityAndHeat) {
  const fs::path p = file("blender279_fire_frame075.vdb");
  Medium m = test::vdb_file_medium(p);
  const VolumeGrids v = load_volume(m, true);
  EXPECT_TRUE(v.warnings.empty());
  ASSERT_TRUE(v.temperature);
  EXPECT_EQ(v.temperature->name, "heat");  // no "temperature" grid: heat comes next
  EXPECT_NEAR(v.density.max_value, 0.193144, 1e-6);
  EXPECT_NEAR(v.temperature->min_value, 0.0010809, 1e-6);
  EXPECT_NEAR(v.temperature->max_value, 1.56721, 1e-5);
  // Anisotropic voxels: the map is diag(1.73238, 1.72260, 1.72004) + translation.
  EXPECT_NEAR(v.density.index_to_world[0][0], 1.7323753, 1e-6);
  EXPECT_NEAR(v.density.index_to_world[1][1], 1.7225976, 1e-6);
  EXPECT_NEAR(v.density.index_to_world[2][2], 1.7200360, 1e-6);
  EXPECT_NEAR(v.density.index_to_world[3][1], -53.141739, 1e-5);
  expect_matches_box_sampler(p, v.density);
  expect_matches_box_sampler(p, *v.temperature);

  m.temperature_grid = "heat old";  // a name with a space
  const VolumeGrids w = load_volume(m, true);
  ASSERT_TRUE(w.temperature);
  EXPECT_NEAR(w.temperature->max_value, 1.57446, 1e-5);
  m.density_grid = "velocity";
  try {
    load_volume(m, true);
    ADD_FAILURE() << "a vec3s grid named as density must be an error";
  } catch (const InputError& e) {
    EXPECT_TRUE(has(e.what(), "vector grid")) << e.what();
  }
}

TEST_F(RealVdb, MantaflowSmokeInfoAndEmptyGrids) {
  const fs::path p = file("blender50_mantaflow_smoke_frame0001.vdb");
  auto meta = info_blocks(p, false);
  EXPECT_EQ(meta.size(), 8u);
  for (const char* name : {"color_b", "color_g", "color_r", "flame"}) {
    EXPECT_TRUE(has(meta[name], "active voxels: 0")) << name << "\n" << meta[name];
    EXPECT_TRUE(has(meta[name], "index bbox: empty")) << name;
  }
  EXPECT_TRUE(has(meta["density"], "voxel size: (0.166667 0.166667 0.166667)")) << meta["density"];
  EXPECT_TRUE(has(meta["density"], "index bbox: [5 5 5]-[18 18 19] (14 x 14 x 15)")) << meta["density"];
  EXPECT_TRUE(has(meta["shadow"], "active voxels: 12696")) << meta["shadow"];
  auto vals = info_blocks(p, true);
  auto [dlo, dhi] = value_range(vals["density"]);
  EXPECT_NEAR(dlo, 0.114746, 1e-6);
  EXPECT_NEAR(dhi, 0.983398, 1e-6);
  auto [tlo, thi] = value_range(vals["temperature"]);
  EXPECT_NEAR(tlo, 1.97461, 1e-5);
  EXPECT_NEAR(thi, 1.97461, 1e-5);
  auto [slo, shi] = value_range(vals["shadow"]);
  EXPECT_EQ(slo, -1.0);
  EXPECT_EQ(shi, -1.0);
}

TEST_F(RealVdb, MantaflowSmokeLoadsAndWarnsOnEmptyGrid) {
  const fs::path p = file("blender50_mantaflow_smoke_frame0001.vdb");
  Medium m = test::vdb_file_medium(p);
  VolumeGrids v = load_volume(m, true);
  EXPECT_TRUE(v.warnings.empty());
  ASSERT_TRUE(v.temperature);
  EXPECT_EQ(v.temperature->name, "temperature");
  EXPECT_NEAR(v.density.min_value, 0.114746, 1e-6);
  EXPECT_NEAR(v.density.max_value, 0.983398, 1e-6);
  EXPECT_NEAR(v.temperature->min_value, 1.97461, 1e-5);
  EXPECT_NEAR(v.temperature->max_value, 1.97461, 1e-5);
  expect_matches_box_sampler(p, v.density);

  m.temperature_grid = "flame";  // exists, but empty at this frame
  v = load_volume(m, true);
  ASSERT_EQ(v.warnings.size(), 1u);
  EXPECT_TRUE(has(v.warnings[0], "temperature grid \"flame\": empty grid")) << v.warnings[0];
  EXPECT_TRUE(v.temperature && v.temperature->empty());
}

}  // namespace
}  // namespace pyrolume
