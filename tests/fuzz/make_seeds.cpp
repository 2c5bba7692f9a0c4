// fuzz_seeds DIR: writes small generated seed inputs for the fuzz targets into
// DIR/{vdb,nvdb,image,obj,scene}/ (tools/fuzz adds the assets/ files). Small on
// purpose: libFuzzer mutates small inputs much faster, and each one here
// reaches a different reader path (grid types, half storage, tiles, NanoVDB;
// EXR pixel types, compressions, tiled files, Y-only, variance; PNG/HDR).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>
#include <ImfTiledOutputFile.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <stb_image_write.h>

#include "support/VdbScenes.h"

namespace fs = std::filesystem;

namespace {

template <class GridT>
typename GridT::Ptr box_grid(const std::string& name, int n, double voxel, float scale) {
  auto g = GridT::create(0);
  g->setName(name);
  g->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
  auto acc = g->getAccessor();
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) acc.setValue({i, j, k}, typename GridT::ValueType(scale * float(1 + i + 2 * j + 3 * k)));
  return g;
}

void write_vdb(const fs::path& p, const openvdb::GridPtrVec& grids, uint32_t compression) {
  openvdb::io::File f(p.string());
  f.setCompression(compression);
  f.write(grids);
  f.close();
}

void vdb_seeds(const fs::path& dir) {
  openvdb::initialize();
  using openvdb::io::COMPRESS_ACTIVE_MASK;
  using openvdb::io::COMPRESS_NONE;
  using openvdb::io::COMPRESS_ZIP;
  auto d = box_grid<openvdb::FloatGrid>("density", 3, 0.1, 0.5f);
  auto t = box_grid<openvdb::FloatGrid>("temperature", 2, 0.2, 300.0f);
  write_vdb(dir / "density_temperature.vdb", {d, t}, COMPRESS_NONE);
  write_vdb(dir / "density_zip.vdb", {d}, COMPRESS_ZIP | COMPRESS_ACTIVE_MASK);
  auto h = box_grid<openvdb::FloatGrid>("density", 2, 0.1, 1.0f);
  h->setSaveFloatAsHalf(true);
  write_vdb(dir / "density_half.vdb", {h}, COMPRESS_ACTIVE_MASK);
  auto dbl = box_grid<openvdb::DoubleGrid>("density", 2, 0.5, 2.0f);
  auto heat = box_grid<openvdb::FloatGrid>("heat", 1, 0.5, 900.0f);
  write_vdb(dir / "double_heat.vdb", {dbl, heat}, COMPRESS_NONE);
  // An active tile: one value for a whole 8^3 leaf's worth of voxels.
  auto tile = openvdb::FloatGrid::create(0);
  tile->setName("density");
  tile->tree().addTile(1, openvdb::Coord(0), 1.5f, true);
  write_vdb(dir / "tile.vdb", {tile}, COMPRESS_NONE);
  auto vec = openvdb::Vec3SGrid::create();
  vec->setName("density");
  vec->tree().setValue({0, 0, 0}, openvdb::Vec3s(1, 2, 3));
  write_vdb(dir / "vector.vdb", {vec}, COMPRESS_NONE);
  auto empty = openvdb::FloatGrid::create(0);
  empty->setName("density");
  write_vdb(dir / "empty.vdb", {empty}, COMPRESS_NONE);
  // Two voxels 999 apart: a tiny file whose dense box (1002^3) is past any
  // memory the loader may take (docs/robustness.md "Limits").
  auto far = openvdb::FloatGrid::create(0);
  far->setName("density");
  far->tree().setValue({0, 0, 0}, 1.0f);
  far->tree().setValue({999, 999, 999}, 1.0f);
  write_vdb(dir / "sparse_far.vdb", {far}, COMPRESS_NONE);
  // NanoVDB (the .nvdb path; load_volume detects the format by magic bytes).
  // The test support library's converter: instantiating openToNanoVDB here
  // as well cost the CI build about a minute of a core.
  pyrolume::test::write_nanovdb_copy(dir / "density_temperature.vdb", dir / "density_temperature.nvdb");
}

// fuzz_nvdb's: NanoVDB copies of the float VDB seeds (every node level,
// tiles, Float16, an empty grid) and a root tile, the one kind of tile
// sparse_in_place hands to OpenVDB. Each written grid holds a whole upper
// node (about 270 KB, mostly zeros) unless it has no voxels at all.
void nvdb_seeds(const fs::path& vdb, const fs::path& dir) {
  using pyrolume::test::write_nanovdb_copy;
  write_nanovdb_copy(vdb / "density_temperature.vdb", dir / "density_temperature.nvdb");
  write_nanovdb_copy(vdb / "density_temperature.vdb", dir / "density_temperature_fp16.nvdb", /*fp16=*/true);
  write_nanovdb_copy(vdb / "tile.vdb", dir / "tile.nvdb");
  write_nanovdb_copy(vdb / "empty.vdb", dir / "empty.nvdb");
  write_nanovdb_copy(pyrolume::test::write_tiles_vdb(dir / "root_tile.vdb", 3, 1), dir / "root_tile.nvdb");
  fs::remove(dir / "root_tile.vdb");
}

void exr_seed(const fs::path& p, int w, int h, const std::vector<std::string>& channels, Imf::PixelType type,
              Imf::Compression compression, bool tiled) {
  Imf::Header header(w, h);
  header.compression() = compression;
  for (const auto& c : channels) header.channels().insert(c, Imf::Channel(type));
  const size_t bytes = type == Imf::HALF ? 2 : 4;
  std::vector<std::vector<char>> planes(channels.size(), std::vector<char>(size_t(w) * h * bytes));
  for (size_t c = 0; c < planes.size(); ++c)
    for (size_t i = 0; i < planes[c].size(); ++i) planes[c][i] = char((i * 37 + c * 11) & 0x3f);
  Imf::FrameBuffer fb;
  for (size_t c = 0; c < channels.size(); ++c)
    fb.insert(channels[c], Imf::Slice(type, planes[c].data(), bytes, bytes * size_t(w)));
  if (tiled) {
    header.setTileDescription(Imf::TileDescription(2, 2, Imf::ONE_LEVEL));
    Imf::TiledOutputFile out(p.c_str(), header);
    out.setFrameBuffer(fb);
    out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
  } else {
    Imf::OutputFile out(p.c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(h);
  }
}

void image_seeds(const fs::path& dir) {
  exr_seed(dir / "rgb_float_zip.exr", 4, 3, {"R", "G", "B"}, Imf::FLOAT, Imf::ZIP_COMPRESSION, false);
  exr_seed(dir / "rgba_half_piz.exr", 5, 4, {"R", "G", "B", "A"}, Imf::HALF, Imf::PIZ_COMPRESSION, false);
  exr_seed(dir / "y_half_rle.exr", 3, 3, {"Y"}, Imf::HALF, Imf::RLE_COMPRESSION, false);
  exr_seed(dir / "variance_none.exr", 2, 2, {"R", "G", "B", "variance.R", "variance.G", "variance.B"}, Imf::FLOAT,
           Imf::NO_COMPRESSION, false);
  exr_seed(dir / "rgb_uint_tiled.exr", 4, 4, {"R", "G", "B"}, Imf::UINT, Imf::ZIPS_COMPRESSION, true);
  exr_seed(dir / "rgb_half_b44.exr", 4, 4, {"R", "G", "B"}, Imf::HALF, Imf::B44_COMPRESSION, false);
  exr_seed(dir / "rgb_half_dwaa.exr", 4, 4, {"R", "G", "B"}, Imf::HALF, Imf::DWAA_COMPRESSION, false);
  // stb_image formats read_image also accepts.
  const unsigned char px[2 * 2 * 3] = {255, 0, 0, 0, 255, 0, 0, 0, 255, 128, 128, 128};
  stbi_write_png((dir / "tiny.png").c_str(), 2, 2, 3, px, 6);
  const float hdr[2 * 1 * 3] = {0.5f, 1.0f, 2.0f, 4.0f, 8.0f, 16.0f};
  stbi_write_hdr((dir / "tiny.hdr").c_str(), 2, 1, 3, hdr);
  // Values no render can sum (NaN, Inf, 3e38) and a 65536 x 1 strip, past
  // every GPU's 2D texture side (docs/robustness.md "Finite by construction").
  {
    Imf::Header header(3, 1);
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    float px[3][3] = {{std::nanf(""), 1.0f, 2.0f}, {INFINITY, -INFINITY, 0.5f}, {3e38f, 3e38f, 3e38f}};
    Imf::FrameBuffer fb;
    for (int c = 0; c < 3; ++c)
      fb.insert(c == 0 ? "R" : c == 1 ? "G" : "B", Imf::Slice(Imf::FLOAT, (char*)&px[0][c], 3 * sizeof(float), 0));
    Imf::OutputFile out((dir / "nonfinite.exr").c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(1);
  }
  std::vector<unsigned char> strip(65536 * 3, 100);
  stbi_write_png((dir / "strip_65536x1.png").c_str(), 65536, 1, 3, strip.data(), 65536 * 3);
}

void text(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary) << s; }

void obj_seeds(const fs::path& dir) {
  text(dir / "triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  text(dir / "quad_nt.obj",
       "o quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
       "g face\nf 1/1/1 2/2/1 3/3/1 4/4/1\n");
  text(dir / "negative_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf -4 -3 -2\nf -1//1 -2//1 -3//1\nvn 0 1 0\n");
  text(dir / "polygon_mtl.obj",
       "mtllib none.mtl\nusemtl x\nv 0 0 0\nv 2 0 0\nv 2 2 0\nv 1 3 0\nv 0 2 0\nvt 0.5 0.5\n"
       "s 1\nf 1/1 2/1 3/1 4/1 5/1\nl 1 2\np 3\n");
  // Numbers tinyobjloader would read as 0 or as an infinite float: refused by line.
  text(dir / "nonfinite.obj", "v 0 0 0\nv nan 0 0\nv 0 inf 0\nv 0 0 1e39\nvn -inf 0 0\nvt NaN 0\nf 1 2 3\n");
}

void scene_seeds(const fs::path& dir) {
  // Keys the assets/ scenes do not use: keyframes on every animated
  // parameter, a plane with a size, a texture, a sphere shape, the optional
  // integrator and emission keys.
  text(dir / "keyed.json", R"({
  "camera": {"position": {"keys": [[0, [0, 1, -6]], [10, [1, 1, -6]]]}, "look_at": {"keys": [[-1, [0, 0, 0]], [5.5, [0, 1, 0]]]},
             "up": [0, 1, 0], "fov_deg": 35},
  "film": {"width": 8, "height": 6, "spp": 2, "exposure": {"keys": [[0, 0.5], [2, -1]]}, "seed": 7},
  "integrator": {"max_depth": 4, "mis": true, "emission_estimator": "collision", "majorant": "global",
                 "majorant_grid": [4, 4, 2]},
  "background": {"rgb": [0.1, 0.2, 0.3]},
  "environment": {"file": "sky.exr", "scale": 0.5, "rotation_deg": 90},
  "media": [
    {"name": "fire", "type": "vdb", "file": "fire_$F4.vdb", "density_grid": "density", "temperature_grid": "flame",
     "density_scale": 2, "downsample": 2, "texture_format": "r32f",
     "temperature": {"scale": 1000, "offset": 300, "cutoff_k": 500},
     "transform": {"translate": [0, 1, 0], "rotate_deg": [0, 90, 0], "scale": [1, 1, 1]},
     "emission": {"scale": {"keys": [[0, 1], [24, 0]]}, "blackbody": "physical", "observer": 10, "adapt_to_k": 6500}},
    {"type": "homogeneous", "sigma_a": [1, 1, 1], "sigma_s": [0.5, 0.5, 0.5], "g": 0.3,
     "bounds": {"box": {"min": [-1, -1, -1], "max": [1, 1, 1]}}, "emission": {"temperature_k": 1500}}
  ],
  "shapes": [
    {"mesh": "m.obj", "transform": {"scale": [2, 2, 2]}, "material": {"diffuse": {"rgb": [0.5, 0.5, 0.5], "texture": "t.png"}}},
    {"sphere": {"center": [0, 0, 0], "radius": 1}},
    {"plane": {"center": [0, 0, 0], "normal": [0, 1, 0], "size": [4, 4]}}
  ]
})");
  // The shapes of issue 28's battery: a repeated key, values beyond float.
  text(dir / "duplicate_keys.json",
       R"({"media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0, 1, 0], "radius": 1, "radius": 2}}}],
  "film": {"width": 8}, "media": []})");
  text(dir / "beyond_float.json", R"({
  "film": {"width": 8, "height": 8, "spp": 1},
  "media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0, 1, 0], "radius": 1}},
             "sigma_a": [1e35, 1, 1], "emission": {"temperature_k": 1500, "scale": 1e38}},
            {"type": "vdb", "file": "fire.vdb", "density_scale": 1e20,
             "transform": {"scale": [1e-300, 1e-300, 1e-300]}}],
  "shapes": [{"plane": {"center": [0, 0, 0], "normal": [1e300, 1e300, 0]}},
             {"mesh": "m.obj", "transform": {"scale": [1e300, 1e300, 1e300]}}]
})");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: fuzz_seeds DIR\n");
    return 1;
  }
  const fs::path root = argv[1];
  for (const char* sub : {"vdb", "nvdb", "image", "obj", "scene"}) fs::create_directories(root / sub);
  vdb_seeds(root / "vdb");
  nvdb_seeds(root / "vdb", root / "nvdb");
  image_seeds(root / "image");
  obj_seeds(root / "obj");
  scene_seeds(root / "scene");
  return 0;
}
