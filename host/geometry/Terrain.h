#pragma once
// The demo's procedural mountain: a heightfield of fractional Brownian motion
// (value noise, Musgrave's fBm; seeded, deterministic) under a Gaussian
// envelope, written as an OBJ with uvs and normals, plus an albedo texture of
// grass and grey-blue rock with almost no red in it, so red light on the
// mountain can only come from the fire. tools/gen_terrain writes both.
#include <cstdint>
#include <string>

#include "image/Image.h"

namespace pyrolume::geometry {

struct TerrainParams {
  uint32_t seed = 7;
  int grid = 81;           // vertices per side (grid−1 quads, 2 triangles each)
  double width = 20.0;     // x and z span [−width/2, width/2], scene units, y up
  double peak = 5.0;       // the highest vertex's height; the rim sits near 0
  int texture_size = 256;  // albedo texture is texture_size²
};

// Height y at (x, z) before scaling to `peak` (>= 0; smooth, so its central
// differences give the normals).
double terrain_height_raw(const TerrainParams& p, double x, double z);

// The OBJ text: "v x y z" (4 decimals), "vt u v" (u = (x + w/2)/w,
// v = (z + w/2)/w: image top = +z edge), "vn" (unit, 4 decimals), faces
// counter-clockwise seen from above (geometric normals point up).
std::string terrain_obj(const TerrainParams& p);

// The albedo texture, linear RGB (write it as PNG: 8-bit sRGB). Every texel has
// red ≤ 0.45 × green in linear terms.
Image terrain_albedo(const TerrainParams& p);

}  // namespace pyrolume::geometry
