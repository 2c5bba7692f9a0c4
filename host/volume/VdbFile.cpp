#include "volume/VdbFile.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <fstream>
#include <mutex>

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
