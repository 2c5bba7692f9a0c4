// VDB loading: voxel-centre convention, per-grid transforms, bad input.
// Every VDB here is written by the test itself with the OpenVDB API.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

#include <glm/gtc/matrix_transform.hpp>
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
using openvdb::Coord;
using openvdb::CoordBBox;
using openvdb::Vec3d;

struct OpenVdbInit {
  OpenVdbInit() { openvdb::initialize(); }
} const init_once;

// Linear fields of WORLD position: trilinear interpolation reproduces them
// exactly, so any lattice or half-voxel mistake shows up as a wrong value.
double f_density(const glm::dvec3& p) { return 2.0 + 0.7 * p.x - 0.3 * p.y + 0.45 * p.z; }
double f_temperature(const glm::dvec3& p) { return 1.0 - 0.2 * p.x + 0.5 * p.y + 0.1 * p.z; }

glm::dvec3 to_glm(const Vec3d& v) { return {v.x(), v.y(), v.z()}; }

openvdb::math::Transform::Ptr scale_translate(double voxel, const Vec3d& t) {
  auto xf = openvdb::math::Transform::createLinearTransform(voxel);
  xf->postTranslate(t);
  return xf;
}

// Fills every voxel of `box` with f(world position of the voxel centre).
template <class GridT, class F>
typename GridT::Ptr make_grid(const std::string& name, openvdb::math::Transform::Ptr xf, const CoordBBox& box, F f) {
  auto g = GridT::create(0);
  g->setName(name);
  g->setTransform(xf);
  auto acc = g->getAccessor();
  for (auto it = box.begin(); it; ++it) {
    const Coord c = *it;
    acc.setValue(c, typename GridT::ValueType(f(to_glm(g->indexToWorld(c)))));
  }
  return g;
}

void write_vdb(const fs::path& p, const openvdb::GridPtrVec& grids) {
  openvdb::io::File f(p.string());
  f.write(grids);
  f.close();
}

using test::vdb_file_medium;

std::string joined(const std::vector<std::string>& w) {
  std::string s;
  for (const auto& x : w) s += x + "\n";
  return s;
}

class VolumeLoader : public ::testing::Test {
 protected:
  fs::path dir = test::temp_dir("volume");
  void TearDown() override { fs::remove_all(dir); }

  // Blender-like pair: density voxel 0.1 shifted (0.05,0,0), temperature voxel
  // 0.25 shifted (-0.3,0.1,0.2): the lattices share no sample points.
  fs::path write_mismatched_pair() {
    auto d = make_grid<openvdb::FloatGrid>("density", scale_translate(0.1, {0.05, 0, 0}),
                                           CoordBBox(Coord(-10, -8, -12), Coord(12, 9, 7)), f_density);
    auto t = make_grid<openvdb::FloatGrid>("temperature", scale_translate(0.25, {-0.3, 0.1, 0.2}),
                                           CoordBBox(Coord(-5, -4, -6), Coord(4, 3, 2)), f_temperature);
    auto p = dir / "pair.vdb";
    write_vdb(p, {d, t});
    return p;
  }
};

TEST_F(VolumeLoader, MismatchedGridsSampleTheirOwnFieldAtEveryWorldPoint) {
  const VolumeGrids v = load_volume(vdb_file_medium(write_mismatched_pair()), true);
  ASSERT_TRUE(v.temperature.has_value());
  EXPECT_TRUE(v.warnings.empty()) << joined(v.warnings);
  // Dense box = active bbox + one voxel of padding.
  EXPECT_EQ(v.density.origin, glm::ivec3(-11, -9, -13));
  EXPECT_EQ(v.density.dims, glm::ivec3(25, 20, 22));
  EXPECT_EQ(v.temperature->origin, glm::ivec3(-6, -5, -7));

  std::mt19937 rng(7);
  auto check = [&](const DenseGrid& g, glm::dvec3 lo_idx, glm::dvec3 hi_idx, double (*f)(const glm::dvec3&)) {
    std::uniform_real_distribution<double> u(0, 1);
    for (int n = 0; n < 2000; ++n) {
      glm::dvec3 idx = lo_idx + glm::dvec3(u(rng), u(rng), u(rng)) * (hi_idx - lo_idx);
      glm::dvec3 p(g.index_to_world * glm::dvec4(idx, 1));
      ASSERT_NEAR(g.sample_world(p), f(p), 1e-5 * std::max(1.0, std::abs(f(p)))) << g.name << " at index " << idx.x
                                                                                 << " " << idx.y << " " << idx.z;
    }
  };
  // Index ranges where all 8 trilinear neighbours are active voxels.
  check(v.density, {-10, -8, -12}, {12, 9, 7}, f_density);
  check(*v.temperature, {-5, -4, -6}, {4, 3, 2}, f_temperature);

  // The same world point answers from each grid's own lattice: a point that is
  // a density voxel centre is not a temperature voxel centre, and vice versa.
  const glm::dvec3 p(0.05 + 0.1 * 3, 0.1 * -2, 0.1 * 1);
  EXPECT_NEAR(v.density.sample_world(p), f_density(p), 1e-5);
  EXPECT_NEAR(v.temperature->sample_world(p), f_temperature(p), 1e-5);
}

TEST_F(VolumeLoader, MatchesOpenVdbBoxSamplerIncludingEdgeBlendWithBackground) {
  const fs::path p = write_mismatched_pair();
  const VolumeGrids v = load_volume(vdb_file_medium(p), true);
  openvdb::io::File f(p.string());
  f.open(false);
  std::mt19937 rng(11);
  for (const char* name : {"density", "temperature"}) {
    auto g = openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid(name));
    const DenseGrid& d = std::string(name) == "density" ? v.density : *v.temperature;
    auto acc = g->getConstAccessor();
    const CoordBBox b = g->evalActiveVoxelBoundingBox();
    // Extend 1.5 voxels past the active box: lookups there blend with (and
    // beyond it are) the background 0.
    std::uniform_real_distribution<double> ux(b.min().x() - 1.5, b.max().x() + 1.5),
        uy(b.min().y() - 1.5, b.max().y() + 1.5), uz(b.min().z() - 1.5, b.max().z() + 1.5);
    int near_edge = 0;
    for (int n = 0; n < 5000; ++n) {
      const Vec3d idx(ux(rng), uy(rng), uz(rng));
      const Vec3d w = g->indexToWorld(idx);
      const double ref = openvdb::tools::BoxSampler::sample(acc, g->worldToIndex(w));
      const double got = d.sample_world(to_glm(w));
      ASSERT_NEAR(got, ref, 1e-5 * std::max(1.0, std::abs(ref))) << name;
      const bool outside = idx.x() < b.min().x() || idx.x() > b.max().x() || idx.y() < b.min().y() ||
                           idx.y() > b.max().y() || idx.z() < b.min().z() || idx.z() > b.max().z();
      near_edge += outside && ref != 0.0;
    }
    EXPECT_GT(near_edge, 100) << "the random points must exercise the background blend";
  }
}

TEST_F(VolumeLoader, IndexToWorldMatchesOpenVdbForRotatedAnisotropicAffineMaps) {
  // A general affine map: anisotropic scale, rotation about a skew axis, shear.
  openvdb::math::Mat4d M = openvdb::math::Mat4d::identity();
  M.preScale(Vec3d(0.2, 0.35, 0.15));
  M.postRotate(openvdb::math::Z_AXIS, 0.6);
  M.postRotate(openvdb::math::X_AXIS, -0.4);
  M.postShear(openvdb::math::X_AXIS, openvdb::math::Y_AXIS, 0.1);
  M.postTranslate(Vec3d(1.5, -2.0, 0.25));
  auto xf = openvdb::math::Transform::createLinearTransform(M);
  auto g = make_grid<openvdb::FloatGrid>("density", xf, CoordBBox(Coord(-4, -3, -5), Coord(6, 5, 4)), f_density);
  const fs::path p = dir / "affine.vdb";
  write_vdb(p, {g});
  const VolumeGrids v = load_volume(vdb_file_medium(p), false);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5, 5);
  for (int n = 0; n < 200; ++n) {
    const Vec3d idx(u(rng), u(rng), u(rng));
    const glm::dvec3 ref = to_glm(g->indexToWorld(idx));
    const glm::dvec3 got(v.density.index_to_world * glm::dvec4(to_glm(idx), 1));
    ASSERT_NEAR(glm::length(got - ref), 0.0, 1e-12);
    const glm::dvec3 back(v.density.world_to_index * glm::dvec4(ref, 1));
    ASSERT_NEAR(glm::length(back - to_glm(idx)), 0.0, 1e-9);
  }
  // And the field is still exact through the sheared lattice.
  std::uniform_real_distribution<double> ui(0, 1);
  for (int n = 0; n < 500; ++n) {
    const glm::dvec3 idx = glm::dvec3(-4, -3, -5) + glm::dvec3(ui(rng), ui(rng), ui(rng)) * glm::dvec3(10, 8, 9);
    const glm::dvec3 w(v.density.index_to_world * glm::dvec4(idx, 1));
    ASSERT_NEAR(v.density.sample_world(w), f_density(w), 1e-5 * std::max(1.0, std::abs(f_density(w))));
  }
}

TEST_F(VolumeLoader, HalfAndDoubleGrids) {
  auto h = make_grid<openvdb::FloatGrid>("density", scale_translate(0.1, {0, 0, 0}),
                                         CoordBBox(Coord(0, 0, 0), Coord(7, 7, 7)), f_density);
  h->setSaveFloatAsHalf(true);
  auto d = make_grid<openvdb::DoubleGrid>("heat", scale_translate(0.2, {0.1, 0, 0}),
                                          CoordBBox(Coord(0, 0, 0), Coord(5, 5, 5)), f_temperature);
  const fs::path p = dir / "half_double.vdb";
  write_vdb(p, {h, d});
  const VolumeGrids v = load_volume(vdb_file_medium(p), true);
  ASSERT_TRUE(v.temperature);
  EXPECT_EQ(v.temperature->name, "heat");  // default: first of temperature, heat, flame
  // Stored as half: 11-bit mantissa, so ~5e-4 relative.
  for (int i = 0; i <= 7; ++i) {
    const glm::dvec3 w(0.1 * i, 0.1 * (7 - i), 0.05 * i);
    EXPECT_NEAR(v.density.sample_world(w), f_density(w), 2e-3 * std::abs(f_density(w)));
  }
  // Half really was stored: not every value is the float one.
  int differs = 0;
  for (int i = 0; i <= 7; ++i) {
    const glm::dvec3 w(0.1 * i, 0.1, 0.3);
    differs += float(v.density.sample_world(w)) != float(f_density(w));
  }
  EXPECT_GT(differs, 0);
  for (int i = 0; i <= 5; ++i) {
    const glm::dvec3 w(0.1 + 0.2 * i, 0.2 * 2, 0.1 * i);
    EXPECT_NEAR(v.temperature->sample_world(w), f_temperature(w), 1e-6);
  }
}

TEST_F(VolumeLoader, VectorGridNamedAsDensityIsAnError) {
  auto vel = openvdb::Vec3SGrid::create();
  vel->setName("density");
  vel->tree().setValue(Coord(0, 0, 0), openvdb::Vec3s(1, 0, 0));
  const fs::path p = dir / "vec.vdb";
  write_vdb(p, {vel});
  try {
    load_volume(vdb_file_medium(p), false);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("vector grid"), std::string::npos) << msg;
    EXPECT_NE(msg.find("density"), std::string::npos) << msg;
    EXPECT_NE(msg.find(p.string()), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line";
  }
}

TEST_F(VolumeLoader, MissingGridListsTheGridsThatExist) {
  const fs::path p = write_mismatched_pair();
  Medium m = vdb_file_medium(p);
  m.density_grid = "smoke";
  try {
    load_volume(m, true);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("\"smoke\""), std::string::npos) << msg;
    EXPECT_NE(msg.find("no such grid"), std::string::npos) << msg;
    EXPECT_NE(msg.find("\"density\""), std::string::npos) << msg;
    EXPECT_NE(msg.find("\"temperature\""), std::string::npos) << msg;
  }
  m = vdb_file_medium(p);
  m.temperature_grid = "flame";
  EXPECT_THROW(load_volume(m, true), InputError);
  EXPECT_NO_THROW(load_volume(m, false));  // not needed: not read, not checked
}

TEST_F(VolumeLoader, MissingFileAndNonVdbFileAreInputErrors) {
  try {
    load_volume(vdb_file_medium(dir / "nope.vdb"), true);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos) << e.what();
  }
  test::write_file(dir / "text.vdb", "this is not a volume\n");
  try {
    load_volume(vdb_file_medium(dir / "text.vdb"), true);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not an OpenVDB"), std::string::npos) << e.what();
  }
  // Right magic bytes, truncated body.
  const fs::path p = write_mismatched_pair();
  std::string bytes = test::read_file(p);
  test::write_file(dir / "truncated.vdb", bytes.substr(0, 40));
  EXPECT_THROW(load_volume(vdb_file_medium(dir / "truncated.vdb"), true), InputError);
  EXPECT_THROW(run_info_command(dir / "text.vdb", false, std::cout), InputError);
}

TEST_F(VolumeLoader, EmptyGridWarnsAndRendersAsNoMedium) {
  auto d = openvdb::FloatGrid::create(0);
  d->setName("density");
  const fs::path p = dir / "empty.vdb";
  write_vdb(p, {d});
  const VolumeGrids v = load_volume(vdb_file_medium(p), true);
  EXPECT_TRUE(v.density.empty());
  EXPECT_EQ(v.density.sample_world({0, 0, 0}), 0.0);
  const std::string w = joined(v.warnings);
  EXPECT_NE(w.find("empty grid"), std::string::npos) << w;
  EXPECT_NE(w.find("renders as no medium"), std::string::npos) << w;
  EXPECT_NE(w.find("no temperature grid"), std::string::npos) << w;
}

TEST_F(VolumeLoader, NanVoxelsBecomeZeroWithACount) {
  auto d = make_grid<openvdb::FloatGrid>("density", scale_translate(1.0, {0, 0, 0}),
                                         CoordBBox(Coord(0, 0, 0), Coord(3, 3, 3)), [](auto) { return 1.0; });
  d->tree().setValue(Coord(1, 1, 1), std::numeric_limits<float>::quiet_NaN());
  d->tree().setValue(Coord(2, 1, 1), std::numeric_limits<float>::infinity());
  d->tree().setValue(Coord(2, 2, 1), -std::numeric_limits<float>::infinity());
  const fs::path p = dir / "nan.vdb";
  write_vdb(p, {d});
  const VolumeGrids v = load_volume(vdb_file_medium(p), false);
  const std::string w = joined(v.warnings);
  EXPECT_NE(w.find("3 NaN/Inf voxels treated as 0"), std::string::npos) << w;
  EXPECT_EQ(v.density.sample_world({1, 1, 1}), 0.0);
  EXPECT_EQ(v.density.sample_world({2, 1, 1}), 0.0);
  EXPECT_EQ(v.density.sample_world({1, 2, 1}), 1.0);
  EXPECT_EQ(v.density.min_value, 0.0f);
  EXPECT_EQ(v.density.max_value, 1.0f);
  for (float x : v.density.values) ASSERT_TRUE(std::isfinite(x));
}

TEST_F(VolumeLoader, NegativeDensityIsClampedTemperatureIsNot) {
  auto d = make_grid<openvdb::FloatGrid>("density", scale_translate(1.0, {0, 0, 0}),
                                         CoordBBox(Coord(0, 0, 0), Coord(2, 2, 2)), [](auto p) { return p.x - 1.0; });
  auto t = make_grid<openvdb::FloatGrid>("temperature", scale_translate(1.0, {0, 0, 0}),
                                         CoordBBox(Coord(0, 0, 0), Coord(2, 2, 2)), [](auto p) { return p.x - 1.0; });
  const fs::path p = dir / "neg.vdb";
  write_vdb(p, {d, t});
  const VolumeGrids v = load_volume(vdb_file_medium(p), true);
  const std::string w = joined(v.warnings);
  EXPECT_NE(w.find("9 negative density voxels clamped to 0"), std::string::npos) << w;
  EXPECT_EQ(v.density.sample_world({0, 1, 1}), 0.0);
  EXPECT_EQ(v.density.min_value, 0.0f);
  EXPECT_EQ(v.temperature->sample_world({0, 1, 1}), -1.0);
  EXPECT_EQ(v.temperature->min_value, -1.0f);
  EXPECT_EQ(w.find("temperature grid"), std::string::npos) << w;
}

TEST_F(VolumeLoader, UnusedGridTypesAreSkippedSilently) {
  // Like a Blender cache: int32 obstacles and a staggered vec3s velocity.
  auto d = make_grid<openvdb::FloatGrid>("density", scale_translate(0.5, {0, 0, 0}),
                                         CoordBBox(Coord(0, 0, 0), Coord(3, 3, 3)), f_density);
  auto heat = make_grid<openvdb::FloatGrid>("heat", scale_translate(0.5, {0, 0, 0}),
                                            CoordBBox(Coord(0, 0, 0), Coord(3, 3, 3)), f_temperature);
  auto flame = make_grid<openvdb::FloatGrid>("flame", scale_translate(0.5, {0, 0, 0}),
                                             CoordBBox(Coord(1, 1, 1), Coord(2, 2, 2)), [](auto) { return 0.5; });
  auto obstacles = openvdb::Int32Grid::create(0);
  obstacles->setName("obstacles");
  obstacles->tree().setValue(Coord(1, 1, 1), 1);
  auto vel = openvdb::Vec3SGrid::create();
  vel->setName("velocity");
  vel->setGridClass(openvdb::GRID_STAGGERED);
  vel->tree().setValue(Coord(0, 0, 0), openvdb::Vec3s(0, 1, 0));
  const fs::path p = dir / "blenderish.vdb";
  write_vdb(p, {obstacles, vel, d, flame, heat});
  VolumeGrids v = load_volume(vdb_file_medium(p), true);
  EXPECT_TRUE(v.warnings.empty()) << joined(v.warnings);
  ASSERT_TRUE(v.temperature);
  EXPECT_EQ(v.temperature->name, "heat");  // heat before flame, whatever the file order
  Medium m = vdb_file_medium(p);
  m.temperature_grid = "flame";
  v = load_volume(m, true);
  EXPECT_EQ(v.temperature->name, "flame");
  EXPECT_EQ(v.temperature->max_value, 0.5f);
  v = load_volume(vdb_file_medium(p), false);
  EXPECT_FALSE(v.temperature);
  m = vdb_file_medium(p);
  m.temperature_grid = "obstacles";
  EXPECT_THROW(load_volume(m, true), InputError);
}

TEST_F(VolumeLoader, DownsampleBoxFiltersALinearFieldExactly) {
  // Active box [0,15]^3 splits into whole 2^3 blocks; the mean of a linear
  // field over a block is its value at the block centre.
  auto d = make_grid<openvdb::FloatGrid>("density", scale_translate(0.1, {0.05, -0.2, 0}),
                                         CoordBBox(Coord(0, 0, 0), Coord(15, 15, 15)), f_density);
  const fs::path p = dir / "ds.vdb";
  write_vdb(p, {d});
  Medium m = vdb_file_medium(p);
  m.downsample = 2;
  const VolumeGrids v = load_volume(m, false);
  EXPECT_EQ(v.density.dims, glm::ivec3(10, 10, 10));  // 8 coarse + 2 padding
  EXPECT_EQ(v.density.origin, glm::ivec3(-1, -1, -1));
  // Coarse voxel 0 covers fine 0..1: centre at fine 0.5 -> world 0.05 + 0.05.
  glm::dvec3 c0(v.density.index_to_world * glm::dvec4(0, 0, 0, 1));
  EXPECT_NEAR(glm::length(c0 - glm::dvec3(0.1, -0.15, 0.05)), 0.0, 1e-12);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0.5, 14.5);  // fine index range of coarse centres 0..7
  for (int n = 0; n < 1000; ++n) {
    const glm::dvec3 w(0.05 + 0.1 * u(rng), -0.2 + 0.1 * u(rng), 0.1 * u(rng));
    ASSERT_NEAR(v.density.sample_world(w), f_density(w), 1e-5 * std::abs(f_density(w)));
  }
  // A partial block at the edge averages in the background.
  auto e = make_grid<openvdb::FloatGrid>("density", scale_translate(1.0, {0, 0, 0}),
                                         CoordBBox(Coord(0, 0, 0), Coord(2, 1, 1)), [](auto) { return 8.0; });
  write_vdb(p, {e});
  const VolumeGrids w = load_volume(m, false);
  EXPECT_EQ(w.density.texel(1, 1, 1), 8.0f);  // block 0: full
  EXPECT_EQ(w.density.texel(2, 1, 1), 4.0f);  // block 1: fine x = 2 only, 4 of 8 voxels
}

TEST_F(VolumeLoader, MediumTransformGoesOnTopOfTheGridMap) {
  // Scale first, then X, Y, Z rotations (right-handed), then translate.
  Transform t;
  t.scale = {2, 1, 1};
  t.rotate_deg = {0, 0, 90};
  glm::dvec3 q(medium_transform_matrix(t) * glm::dvec4(1, 0, 0, 1));
  EXPECT_NEAR(glm::length(q - glm::dvec3(0, 2, 0)), 0, 1e-12);
  t = Transform{};
  t.rotate_deg = {90, 90, 0};  // X first: y -> z, then Y: z -> x
  q = glm::dvec3(medium_transform_matrix(t) * glm::dvec4(0, 1, 0, 1));
  EXPECT_NEAR(glm::length(q - glm::dvec3(1, 0, 0)), 0, 1e-12);

  // A single hot voxel at index (2,0,0) of a 0.5 grid shifted by (1,0,0):
  // world (2,0,0); rotated 90 about Z -> (0,2,0); translated -> (10,2,-1).
  auto d = openvdb::FloatGrid::create(0);
  d->setName("density");
  d->setTransform(scale_translate(0.5, {1, 0, 0}));
  d->tree().setValue(Coord(2, 0, 0), 3.0f);
  const fs::path p = dir / "xf.vdb";
  write_vdb(p, {d});
  Medium m = vdb_file_medium(p);
  m.transform.rotate_deg = {0, 0, 90};
  m.transform.translate = {10, 0, -1};
  const VolumeGrids v = load_volume(m, false);
  const glm::dvec3 w(v.density.index_to_world * glm::dvec4(2, 0, 0, 1));
  EXPECT_NEAR(glm::length(w - glm::dvec3(10, 2, -1)), 0, 1e-12);
  EXPECT_NEAR(v.density.sample_world({10, 2, -1}), 3.0, 1e-6);
  EXPECT_NEAR(v.density.sample_world({12, 0, -1}), 0.0, 1e-6);  // where it would be without rotation
  glm::dvec3 lo, hi;
  v.density.world_bounds(lo, hi);
  EXPECT_NEAR(lo.x, 9.5, 1e-12);
  EXPECT_NEAR(hi.x, 10.5, 1e-12);
  EXPECT_NEAR(lo.y, 1.5, 1e-12);
  EXPECT_NEAR(hi.y, 2.5, 1e-12);
}

TEST_F(VolumeLoader, NanoVdbLoadsToTheSameTexturesAsOpenVdb) {
  const fs::path vdb = write_mismatched_pair();
  const fs::path nvdb = dir / "pair.nvdb";
  test::write_nanovdb_copy(vdb, nvdb);  // both grids, density and temperature

  Medium mv = vdb_file_medium(vdb), mn = vdb_file_medium(nvdb);
  mv.transform.translate = mn.transform.translate = {0.5, 1, 2};
  const VolumeGrids a = load_volume(mv, true), b = load_volume(mn, true);
  ASSERT_TRUE(b.temperature);
  EXPECT_TRUE(b.warnings.empty()) << joined(b.warnings);
  auto same = [](const DenseGrid& x, const DenseGrid& y) {
    EXPECT_EQ(x.name, y.name);
    EXPECT_EQ(x.dims, y.dims);
    EXPECT_EQ(x.origin, y.origin);
    EXPECT_EQ(x.values, y.values);
    EXPECT_EQ(x.min_value, y.min_value);
    EXPECT_EQ(x.max_value, y.max_value);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(glm::length(x.index_to_world[c] - y.index_to_world[c]), 0, 1e-12);
  };
  same(a.density, b.density);
  same(*a.temperature, *b.temperature);

  std::ostringstream info;
  EXPECT_EQ(run_info_command(nvdb, false, info), 0);
  EXPECT_NE(info.str().find("grid \"temperature\""), std::string::npos) << info.str();
  EXPECT_NE(info.str().find("active voxels: 8280"), std::string::npos) << info.str();  // 23 x 18 x 20
}

TEST_F(VolumeLoader, InfoPrintsEveryGridFromMetadataAndFromValues) {
  const fs::path p = write_mismatched_pair();
  std::ostringstream meta, vals;
  EXPECT_EQ(run_info_command(p, false, meta), 0);
  EXPECT_EQ(run_info_command(p, true, vals), 0);
  for (const std::string& s : {meta.str(), vals.str()}) {
    EXPECT_NE(s.find("grid \"density\"\n  type: float, class: unknown"), std::string::npos) << s;
    EXPECT_NE(s.find("voxel size: (0.1 0.1 0.1)"), std::string::npos) << s;
    EXPECT_NE(s.find("transform: scale (0.1 0.1 0.1), translation (0.05 0 0)"), std::string::npos) << s;
    EXPECT_NE(s.find("active voxels: 8280"), std::string::npos) << s;  // 23 x 18 x 20
    EXPECT_NE(s.find("index bbox: [-10 -8 -12]-[12 9 7] (23 x 18 x 20)"), std::string::npos) << s;
    EXPECT_NE(s.find("grid \"temperature\""), std::string::npos) << s;
    EXPECT_NE(s.find("voxel size: (0.25 0.25 0.25)"), std::string::npos) << s;
  }
  EXPECT_NE(meta.str().find("values: unknown"), std::string::npos) << meta.str();
  // Extremes of the linear density at opposite corners of its active box.
  const double lo = f_density({-0.95, 0.9, -1.2}), hi = f_density({1.25, -0.8, 0.7});
  std::ostringstream range;
  range << "values: [" << float(lo) << ", " << float(hi) << "]";
  EXPECT_NE(vals.str().find(range.str()), std::string::npos) << vals.str() << "\nwanted " << range.str();
}

}  // namespace
}  // namespace pyrolume
