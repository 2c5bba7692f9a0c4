// The OpenVDB (and NanoVDB) writing half of VdbScenes.h, in one translation
// unit so that the tests which only need small .vdb files do not instantiate
// OpenVDB's tree templates each. openToNanoVDB is converted for FloatGrid
// only: its GridBase overload instantiates the converter for 13 grid types,
// which made this file the slowest of the build (~2 min of a CI core).
#include "support/VdbScenes.h"

#include <stdexcept>

#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

namespace pyrolume::test {
namespace {

void ensure_openvdb() {
  static const bool once = [] {
    openvdb::initialize();
    return true;
  }();
  (void)once;
}

openvdb::math::Transform::Ptr lattice_transform(const Lattice& l) {
  auto xf = openvdb::math::Transform::createLinearTransform(l.voxel);
  xf->postTranslate(openvdb::Vec3d(l.offset.x, l.offset.y, l.offset.z));
  return xf;
}

openvdb::FloatGrid::Ptr build(const FloatGridSpec& spec) {
  auto g = openvdb::FloatGrid::create(0.0f);
  g->setName(spec.name);
  g->setTransform(lattice_transform(spec.lattice));
  g->setGridClass(openvdb::GRID_FOG_VOLUME);
  auto acc = g->getAccessor();
  const VoxelBox& box = spec.box;
  for (int k = box.lo.z; k <= box.hi.z; ++k)
    for (int j = box.lo.y; j <= box.hi.y; ++j)
      for (int i = box.lo.x; i <= box.hi.x; ++i) acc.setValueOn(openvdb::Coord(i, j, k), spec.value(i, j, k));
  return g;
}

std::filesystem::path write_grids(const std::filesystem::path& file, const openvdb::GridPtrVec& grids,
                                  const FileMetadata& metadata = {}) {
  openvdb::io::File f(file.string());
  openvdb::MetaMap meta;
  for (const auto& [key, value] : metadata) meta.insertMeta(key, openvdb::StringMetadata(value));
  f.write(grids, meta);
  f.close();
  return file;
}

}  // namespace

std::filesystem::path write_vdb(const std::filesystem::path& file, const std::vector<FloatGridSpec>& grids,
                                const FileMetadata& metadata) {
  ensure_openvdb();
  openvdb::GridPtrVec out;
  for (const FloatGridSpec& spec : grids) out.push_back(build(spec));
  return write_grids(file, out, metadata);
}

std::filesystem::path write_two_voxels_vdb(const std::filesystem::path& file, const glm::ivec3& far) {
  ensure_openvdb();
  auto g = openvdb::FloatGrid::create(0.0f);
  g->setName("density");
  g->tree().setValueOn(openvdb::Coord(0, 0, 0), 1.0f);
  g->tree().setValueOn(openvdb::Coord(far.x, far.y, far.z), 1.0f);
  return write_grids(file, {g});
}

std::filesystem::path write_tiles_vdb(const std::filesystem::path& file, int level, int n) {
  ensure_openvdb();
  auto g = openvdb::FloatGrid::create(0.0f);
  g->setName("density");
  const int side = level == 1 ? 8 : level == 2 ? 128 : 4096;
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) g->tree().addTile(level, openvdb::Coord(i * side, j * side, k * side), 1.0f, true);
  return write_grids(file, {g});
}

std::filesystem::path write_reader_paths_vdb(const std::filesystem::path& file, VdbCompression compression) {
  ensure_openvdb();
  auto d = openvdb::FloatGrid::create(0);
  d->setName("density");
  d->setTransform(openvdb::math::Transform::createLinearTransform(0.1));
  for (int i = 0; i < 3; ++i) d->tree().setValue({i, i, 2 * i}, 0.5f + float(i));
  d->tree().addTile(1, openvdb::Coord(64, 0, 0), 2.0f, true);
  d->setSaveFloatAsHalf(true);
  auto t = openvdb::FloatGrid::create(0);
  t->setName("temperature");
  t->tree().setValue({1, 1, 1}, 1500.0f);
  openvdb::MetaMap meta;
  meta.insertMeta("creator", openvdb::StringMetadata("corrupt_input_test"));
  openvdb::io::File f(file.string());
  f.setCompression(compression == VdbCompression::ZipActiveMask ? openvdb::io::COMPRESS_ZIP |
                                                                       openvdb::io::COMPRESS_ACTIVE_MASK
                   : compression == VdbCompression::Blosc ? openvdb::io::COMPRESS_BLOSC
                                                          : openvdb::io::COMPRESS_NONE);
  f.write({d, t}, meta);
  f.close();
  return file;
}

void write_nanovdb_copy(const std::filesystem::path& vdb, const std::filesystem::path& nvdb, bool fp16) {
  ensure_openvdb();
  openvdb::io::File f(vdb.string());
  f.open(false);
  std::vector<nanovdb::GridHandle<nanovdb::HostBuffer>> handles;
  for (auto it = f.beginName(); it != f.endName(); ++it) {
    const auto g = openvdb::gridPtrCast<openvdb::FloatGrid>(f.readGrid(*it));
    if (!g) throw std::runtime_error("write_nanovdb_copy: grid '" + *it + "' of " + vdb.string() + " is not float");
    handles.push_back(fp16 ? nanovdb::openToNanoVDB<nanovdb::HostBuffer, openvdb::FloatTree, nanovdb::Fp16>(*g)
                           : nanovdb::openToNanoVDB(*g));
  }
  f.close();
  nanovdb::io::writeGrids<nanovdb::HostBuffer, std::vector>(nvdb.string(), handles);
}

std::filesystem::path write_explosion_shell_vdb(const std::filesystem::path& file, const Lattice& l, double r_inner,
                                                double r_outer, float peak_density, float t_inner_k,
                                                float t_outer_k) {
  ensure_openvdb();
  auto make = [&](const std::string& name, bool temperature) {
    auto g = openvdb::FloatGrid::create(0.0f);
    g->setName(name);
    g->setTransform(lattice_transform(l));
    auto acc = g->getAccessor();
    const int R = int(std::ceil(r_outer));
    for (int k = -R; k <= R; ++k)
      for (int j = -R; j <= R; ++j)
        for (int i = -R; i <= R; ++i) {
          const double r = std::sqrt(double(i * i + j * j + k * k));
          if (r < r_inner || r > r_outer) continue;
          const double s = (r - r_inner) / (r_outer - r_inner);  // 0 inner .. 1 outer
          const float v = temperature ? float(t_inner_k + (t_outer_k - t_inner_k) * s)
                                      : float(peak_density * std::sin(3.14159265358979 * s));
          acc.setValueOn(openvdb::Coord(i, j, k), v);
        }
    return g;
  };
  return write_grids(file, {make("density", false), make("temperature", true)});
}

}  // namespace pyrolume::test
