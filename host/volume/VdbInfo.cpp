#include "volume/VdbInfo.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>
#include <string>

#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/IO.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "util/Error.h"
#include "volume/NanoVdbValidate.h"
#include "volume/SourceConventions.h"
#include "volume/SparseGrid.h"
#include "volume/VdbFile.h"

namespace pyrolume {
namespace {

using GridReport = GridInfo;

std::string vec3(const glm::dvec3& v) {
  std::ostringstream s;
  s << v.x << ' ' << v.y << ' ' << v.z;
  return s.str();
}

std::string transform_text(const glm::dmat4& M) {
  bool diagonal = true;
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r)
      if (r != c && M[c][r] != 0.0) diagonal = false;
  std::ostringstream s;
  if (diagonal) {
    s << "scale (" << vec3({M[0][0], M[1][1], M[2][2]}) << "), translation (" << vec3(glm::dvec3(M[3])) << ")";
  } else {
    // Rows of the column-vector matrix: world = M * (i, j, k, 1).
    s << "matrix [";
    for (int r = 0; r < 3; ++r) s << (r ? "; " : "") << M[0][r] << ' ' << M[1][r] << ' ' << M[2][r] << ' ' << M[3][r];
    s << "]";
  }
  return s.str();
}

}  // namespace

std::string footprint_text(double bytes) {
  char b[32];
  if (bytes >= double(1ull << 30)) std::snprintf(b, sizeof b, "%.1f GiB", bytes / double(1ull << 30));
  else if (bytes >= double(1 << 20)) std::snprintf(b, sizeof b, "%.1f MiB", bytes / double(1 << 20));
  else if (bytes >= 1024.0) std::snprintf(b, sizeof b, "%.1f KiB", bytes / 1024.0);
  else std::snprintf(b, sizeof b, "%.0f B", bytes);
  return b;
}

namespace {

// What the grid would take as a dense R16F texture (its active box with one
// voxel of padding, 2 B a texel) and as a sparse NanoVDB float tree
// (docs/volumes.md "Sparse grids"; texture_format "auto" chooses between them).
void print_footprints(const GridReport& g, std::ostream& out) {
  if (!g.bbox_min || !g.bbox_max || (g.active_voxels && *g.active_voxels == 0)) return;
  auto mib = [](double bytes) { return footprint_text(bytes); };
  const glm::dvec3 d = glm::dvec3(*g.bbox_max - *g.bbox_min) + 3.0;
  out << "  memory: dense " << mib(2.0 * d.x * d.y * d.z) << " (R16F over the active box); sparse ";
  if (g.nodes)
    out << mib(double(nanovdb_float_bytes(g.nodes->x, g.nodes->y, g.nodes->z))) << " (NanoVDB, " << g.nodes->x
        << " leaves)\n";
  else if (g.active_voxels)
    out << "at least " << mib(4.0 * double(*g.active_voxels)) << " (4 B an active voxel; --values counts the leaves)\n";
  else
    out << "unknown (use --values)\n";
}

void print_report(const GridReport& g, std::ostream& out) {
  out << "grid \"" << g.name << "\"\n";
  out << "  type: " << g.type << (g.saved_as_half ? " (saved as half)" : "") << ", class: " << g.grid_class << "\n";
  out << "  voxel size: (" << vec3(g.voxel_size) << ")\n";
  out << "  transform: " << transform_text(g.index_to_world) << "\n";
  out << "  active voxels: ";
  if (g.active_voxels) out << *g.active_voxels << "\n";
  else out << "unknown (not in metadata; use --values)\n";
  const bool empty = g.active_voxels && *g.active_voxels == 0;
  if (empty || !g.bbox_min || !g.bbox_max) {
    const char* why = empty ? "empty" : "unknown (not in metadata; use --values)";
    out << "  index bbox: " << why << "\n  world bbox: " << why << "\n";
  } else {
    const glm::i64vec3 lo = *g.bbox_min, hi = *g.bbox_max, d = hi - lo + int64_t(1);
    out << "  index bbox: [" << lo.x << ' ' << lo.y << ' ' << lo.z << "]-[" << hi.x << ' ' << hi.y << ' ' << hi.z
        << "] (" << d.x << " x " << d.y << " x " << d.z << ")\n";
    const auto [wlo, whi] = *g.world_bbox();
    out << "  world bbox: [" << vec3(wlo) << "]-[" << vec3(whi) << "]\n";
  }
  out << "  " << g.range_label << ": ";
  if (empty) out << "none (empty grid)";
  else if (g.min_value && g.max_value) out << "[" << *g.min_value << ", " << *g.max_value << "]";
  else out << "unknown (" << (g.note.empty() ? "not in metadata; use --values" : g.note) << ")";
  if (g.nonfinite) out << ", " << g.nonfinite << " NaN/Inf voxels";
  out << "\n";
  print_footprints(g, out);
}

// ---- OpenVDB ----

template <class T>
double magnitude(const T& v) {
  if constexpr (std::is_arithmetic_v<T>) return double(v);
  else return double(v.length());
}

// Exact statistics from the active voxels and tiles.
template <class GridT>
void scan_values(const GridT& grid, GridReport& r) {
  using ValueT = typename GridT::ValueType;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  uint64_t bad = 0;
  for (auto it = grid.tree().cbeginValueOn(); it; ++it) {
    const double v = magnitude<ValueT>(*it);
    if (!std::isfinite(v)) {
      bad += it.getVoxelCount();
      continue;
    }
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (lo <= hi) {
    r.min_value = lo;
    r.max_value = hi;
  }
  r.nonfinite = bad;
  if constexpr (!std::is_arithmetic_v<ValueT>) r.range_label = "|values|";
}

void fill_from_values(const openvdb::GridBase& g, GridReport& r) {
  r.active_voxels = g.activeVoxelCount();
  const openvdb::CoordBBox b = g.evalActiveVoxelBoundingBox();
  if (!b.empty()) {
    r.bbox_min = glm::i64vec3(b.min().x(), b.min().y(), b.min().z());
    r.bbox_max = glm::i64vec3(b.max().x(), b.max().y(), b.max().z());
  }
  bool done = g.apply<openvdb::TypeList<openvdb::FloatGrid, openvdb::DoubleGrid, openvdb::Int32Grid, openvdb::Int64Grid,
                                        openvdb::Vec3SGrid, openvdb::Vec3DGrid, openvdb::Vec3IGrid>>(
      [&](const auto& typed) { scan_values(typed, r); });
  if (!done) r.note = "no value range for " + r.type + " grids";
  const std::vector<openvdb::Index32> n = g.baseTree().nodeCount();
  if (n.size() >= 3) r.nodes = glm::u64vec3(n[0], n[1], n[2]);
}

void fill_from_metadata(const openvdb::GridBase& g, GridReport& r) {
  if (auto n = g.getMetadata<openvdb::Int64Metadata>(openvdb::GridBase::META_FILE_VOXEL_COUNT))
    r.active_voxels = uint64_t(n->value());
  auto lo = g.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MIN);
  auto hi = g.getMetadata<openvdb::Vec3IMetadata>(openvdb::GridBase::META_FILE_BBOX_MAX);
  if (lo && hi) {
    r.bbox_min = glm::i64vec3(lo->value().x(), lo->value().y(), lo->value().z());
    r.bbox_max = glm::i64vec3(hi->value().x(), hi->value().y(), hi->value().z());
  }
  // OpenVDB writes no value statistics, so the range needs --values.
}

GridReport report_openvdb(const openvdb::GridBase& g, const std::string& file) {
  GridReport r;
  r.name = g.getName();
  r.type = g.valueType();
  r.grid_class = openvdb::GridBase::gridClassToString(g.getGridClass());
  r.saved_as_half = g.saveFloatAsHalf();
  const openvdb::Vec3d vs = g.voxelSize();
  r.voxel_size = glm::dvec3(vs.x(), vs.y(), vs.z());
  r.index_to_world = openvdb_index_to_world(g.transform(), file, r.name);
  return r;
}

VolumeFileInfo read_openvdb_info(const std::string& file, bool values, const std::string& only_grid) {
  auto wanted = [&](const std::string& name) { return values && (only_grid.empty() || name == only_grid); };
  ensure_openvdb_initialized();
  // OpenVDB trusts the lengths and offsets it reads: check them first, and
  // with --values read only the trees the check walked.
  const std::vector<std::string> walked =
      validate_openvdb_file(file, wanted);
  VolumeFileInfo info;
  info.file = file;
  try {
    openvdb::io::File f(file);
    f.open(/*delayLoad=*/false);
    if (auto meta = f.getMetadata())
      for (auto it = meta->beginMeta(); it != meta->endMeta(); ++it)
        if (it->second) info.metadata.emplace_back(it->first, it->second->str());
    info.format_text = "OpenVDB, file format " + f.version();
    std::vector<std::string> names;
    for (auto it = f.beginName(); it != f.endName(); ++it) names.push_back(*it);
    // Per grid, so that one unregistered grid type spoils only its own entry.
    for (const std::string& name : names) {
      openvdb::GridBase::Ptr g;
      const bool read_values = wanted(name) && std::find(walked.begin(), walked.end(), name) != walked.end();
      try {
        g = read_values ? f.readGrid(name) : f.readGridMetadata(name);
      } catch (const openvdb::Exception& e) {
        GridReport r;
        r.name = name;
        r.unreadable = e.what();
        info.grids.push_back(r);
        continue;
      }
      GridReport r = report_openvdb(*g, file);
      if (read_values) fill_from_values(*g, r);
      else fill_from_metadata(*g, r);
      if (wanted(name) && !read_values) r.note = "values not read: " + r.type + " trees are not checked";
      info.grids.push_back(r);
    }
  } catch (const openvdb::Exception& e) {
    throw input_error(file, "", std::string("cannot read as OpenVDB: ") + e.what());
  }
  return info;
}

// ---- NanoVDB ----

template <class BuildT>
void nano_grid(const nanovdb::NanoGrid<BuildT>& grid, bool values, GridReport& r) {
  r.index_to_world = nanovdb_index_to_world(grid);
  r.nodes = glm::u64vec3(grid.tree().nodeCount(0), grid.tree().nodeCount(1), grid.tree().nodeCount(2));
  if (!values) {
    // NanoVDB keeps min/max of the active values in the root node (when the
    // grid was built with stats).
    if (grid.hasMinMax()) {
      r.min_value = double(grid.tree().root().minimum());
      r.max_value = double(grid.tree().root().maximum());
    } else {
      r.note = "not stored; use --values";
    }
    return;
  }
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  const auto& b = grid.indexBBox();
  auto acc = grid.getAccessor();
  uint64_t n = 0;
  // Visits every voxel of the box: refuse boxes too large to scan (a corrupt
  // or huge bbox would run for hours). int64 counters: the box may end at INT32_MAX.
  uint64_t box = 1;
  for (int a = 0; a < 3; ++a) box *= uint64_t(std::max<int64_t>(0, int64_t(b.max()[a]) - b.min()[a] + 1));
  if (box > (uint64_t(1) << 27)) {
    r.note = "index bbox of " + std::to_string(box) + " voxels is too large to scan";
    return;
  }
  if (grid.activeVoxelCount() > 0)
    for (int64_t k = b.min()[2]; k <= b.max()[2]; ++k)
      for (int64_t j = b.min()[1]; j <= b.max()[1]; ++j)
        for (int64_t i = b.min()[0]; i <= b.max()[0]; ++i) {
          const nanovdb::Coord ijk{int32_t(i), int32_t(j), int32_t(k)};
          if (!acc.isActive(ijk)) continue;
          ++n;
          const double v = double(acc.getValue(ijk));
          if (!std::isfinite(v)) {
            ++r.nonfinite;
            continue;
          }
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
  r.active_voxels = n;
  if (lo <= hi) {
    r.min_value = lo;
    r.max_value = hi;
  }
}

VolumeFileInfo read_nanovdb_info(const std::string& file, bool values_asked, const std::string& only_grid) {
  std::vector<nanovdb::io::GridMetaData> metas;
  validate_nanovdb_file(file);  // nanovdb::io allocates by the sizes it reads
  try {
    metas = nanovdb::io::readGridMetaData(file);
  } catch (const std::exception& e) {
    throw input_error(file, "", std::string("cannot read as NanoVDB: ") + e.what());
  }
  VolumeFileInfo info;
  info.file = file;
  info.format_text = "NanoVDB";
  for (size_t n = 0; n < metas.size(); ++n) {
    const auto& md = metas[n];
    const bool values = values_asked && (only_grid.empty() || md.gridName == only_grid);
    GridReport r;
    r.name = md.gridName;
    r.type = nanovdb::toStr(md.gridType);
    r.grid_class = nanovdb::toStr(md.gridClass);
    r.voxel_size = glm::dvec3(md.voxelSize[0], md.voxelSize[1], md.voxelSize[2]);
    r.active_voxels = md.voxelCount;
    if (md.voxelCount > 0) {
      r.bbox_min = glm::i64vec3(md.indexBBox.min()[0], md.indexBBox.min()[1], md.indexBBox.min()[2]);
      r.bbox_max = glm::i64vec3(md.indexBBox.max()[0], md.indexBBox.max()[1], md.indexBBox.max()[2]);
    }
    // The transform and the value range live in the grid itself, not in the
    // file's metadata; a NanoVDB grid is read as one flat buffer, no tree build.
    nanovdb::GridHandle<nanovdb::HostBuffer> h;
    try {
      h = nanovdb::io::readGrid<nanovdb::HostBuffer>(file, n);
    } catch (const std::exception& e) {
      r.note = std::string("grid unreadable: ") + e.what();
    }
    if (h) validate_nanovdb_grid(h, file, r.name, &md);  // before any accessor follows its offsets
    if (h) {
      if (auto* g = h.grid<float>()) nano_grid(*g, values, r);
      else if (auto* g = h.grid<double>()) nano_grid(*g, values, r);
      else if (auto* g = h.grid<nanovdb::Fp16>()) nano_grid(*g, values, r);
      else if (auto* g = h.grid<nanovdb::Fp8>()) nano_grid(*g, values, r);
      else if (auto* g = h.grid<nanovdb::Fp4>()) nano_grid(*g, values, r);
      else if (auto* g = h.grid<nanovdb::FpN>()) nano_grid(*g, values, r);
      else r.note = "no value range for " + r.type + " grids";
    }
    info.grids.push_back(r);
  }
  return info;
}

}  // namespace

std::optional<std::pair<glm::dvec3, glm::dvec3>> GridInfo::world_bbox() const {
  if (!bbox_min || !bbox_max || (active_voxels && *active_voxels == 0)) return std::nullopt;
  const glm::i64vec3 lo = *bbox_min, hi = *bbox_max;
  // The outer voxel faces: voxel ijk covers index ijk +- 0.5 (cell-centred).
  glm::dvec3 wlo(std::numeric_limits<double>::infinity()), whi(-std::numeric_limits<double>::infinity());
  for (int c = 0; c < 8; ++c) {
    glm::dvec3 q((c & 1) ? hi.x + 0.5 : lo.x - 0.5, (c & 2) ? hi.y + 0.5 : lo.y - 0.5, (c & 4) ? hi.z + 0.5 : lo.z - 0.5);
    glm::dvec3 w(index_to_world * glm::dvec4(q, 1.0));
    wlo = glm::min(wlo, w);
    whi = glm::max(whi, w);
  }
  return std::make_pair(wlo, whi);
}

const GridInfo* VolumeFileInfo::grid(const std::string& name) const {
  for (const auto& g : grids)
    if (g.name == name && g.unreadable.empty()) return &g;
  return nullptr;
}

std::string VolumeFileInfo::metadata_value(const std::string& key) const {
  for (const auto& [k, v] : metadata)
    if (k == key) return v;
  return "";
}

VolumeFileInfo read_volume_file_info(const std::filesystem::path& file, bool values, const std::string& only_grid) {
  return detect_volume_format(file) == VolumeFormat::NanoVdb ? read_nanovdb_info(file.string(), values, only_grid)
                                                             : read_openvdb_info(file.string(), values, only_grid);
}

int run_info_command(const std::filesystem::path& file, bool values, std::ostream& out) {
  const VolumeFileInfo info = read_volume_file_info(file, values);
  print_volume_file_info(info, out);
  SourceConvention c = source_convention(info, VolumeSource::Auto);
  fit_temperature_mapping(c, file.string());
  settle_emission(c, file.string());
  out << "scene:\n  " << scene_snippet(file.string(), c);
  return 0;
}

void print_volume_file_info(const VolumeFileInfo& info, std::ostream& out) {
  const size_t n = info.grids.size();
  out << "file \"" << info.file << "\": " << info.format_text;
  if (const std::string creator = info.metadata_value("creator"); !creator.empty()) out << ", creator \"" << creator << "\"";
  out << ", " << n << (n == 1 ? " grid\n" : " grids\n");
  for (const auto& [key, value] : info.metadata) {
    if (key == "creator") continue;
    std::string one_line = value;  // matrices print over several lines
    for (char& c : one_line)
      if (c == '\n' || c == '\r') c = ' ';
    out << "metadata \"" << key << "\": " << one_line << "\n";
  }
  for (const GridInfo& g : info.grids) {
    if (!g.unreadable.empty()) out << "grid \"" << g.name << "\"\n  unreadable: " << g.unreadable << "\n";
    else print_report(g, out);
  }
}

}  // namespace pyrolume
