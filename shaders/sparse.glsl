// Sparse grids (texture_format "sparse"): NanoVDB trees read through PNanoVDB,
// the NanoVDB project's portable C/HLSL/GLSL reader (libnanovdb-dev). Every
// tree sits in one uniform texel buffer of rgba32ui (BINDING_SPARSE; texel
// buffers gather about as fast as 3D textures on lavapipe, storage buffers at
// less than half the speed), at the byte offset GpuGrid density.tree /
// temperature.tree gives. A lookup finds its leaf in a flat table of leaf
// addresses instead of walking the tree from the root: PNanoVDB's walk
// branches differently in every SIMD lane, ran at 0.4× the dense texture's
// speed, and made lavapipe's pipeline compile take 20 s (docs/volumes.md
// "Sparse grids").
#define PNANOVDB_GLSL
#define PNANOVDB_BUF_CUSTOM
#define pnanovdb_buf_t uint
uint pnanovdb_buf_read_uint32(pnanovdb_buf_t buf, uint byte_offset) {
  return texelFetch(sparse_tex, int(byte_offset >> 4u))[(byte_offset >> 2u) & 3u];
}
uvec2 pnanovdb_buf_read_uint64(pnanovdb_buf_t buf, uint byte_offset) {
  const uvec4 q = texelFetch(sparse_tex, int(byte_offset >> 4u));  // 8-byte aligned: one texel
  return (byte_offset & 8u) != 0u ? q.zw : q.xy;
}
#define pnanovdb_grid_type_t uint
#define PNANOVDB_GRID_TYPE_GET(grid_typeIn, nameIn) pnanovdb_grid_type_constants[grid_typeIn].nameIn
#include "nanovdb/PNanoVDB.h"

// The byte offset of voxel ijk's value, through the grid's flat leaf table
// (GpuGrid *_leaf_*): one table read and no branch, where the walk from the
// root branches differently in every lane of a SIMD group. Outside the table,
// and in a leaf the tree lacks, it is a value of the zero leaf.
uint sparse_value_address(uint table, ivec3 leaf_origin, uvec3 dims, ivec3 ijk) {
  const uvec3 L = uvec3((ijk >> 3) - leaf_origin);  // below the origin wraps past dims
  const bool inside = all(lessThan(L, dims));
  const uvec3 Lc = min(L, dims - 1u);
  const uint leaf = pnanovdb_buf_read_uint32(0u, table + 4u * ((Lc.z * dims.y + Lc.y) * dims.x + Lc.x));
  return (inside ? leaf : SPARSE_ZERO_LEAF) + 4u * pnanovdb_leaf_coord_to_offset(ijk);
}

// Trilinear lookup of the float tree whose leaf table is at byte offset
// `table`, at index position p: OpenVDB's BoxSampler convention (voxel ijk's
// value sits at the integer point ijk), as the dense textures are sampled; 0
// where no leaf is.
float sparse_trilinear(uint table, ivec3 leaf_origin, uvec3 leaf_dims, vec3 p) {
  const vec3 p0 = floor(p);
  const ivec3 i0 = ivec3(p0);
  const vec3 f = p - p0;
  float v[8];
  for (int c = 0; c < 8; ++c) {
    const ivec3 ijk = i0 + ivec3(c & 1, (c >> 1) & 1, c >> 2);
    pnanovdb_address_t at;
    at.byte_offset = sparse_value_address(table, leaf_origin, leaf_dims, ijk);
    v[c] = pnanovdb_read_float(0u, at);
  }
  const vec4 x = mix(vec4(v[0], v[2], v[4], v[6]), vec4(v[1], v[3], v[5], v[7]), f.x);
  const vec2 y = mix(x.xz, x.yw, f.y);
  return mix(y.x, y.y, f.z);
}
