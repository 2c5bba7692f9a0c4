// The generated mountain (tools/gen_terrain, host/geometry/Terrain): the
// committed assets are what the generator writes, the albedo has no red to
// speak of, and the mesh has the promised size, shape and orientation.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "geometry/Mesh.h"
#include "geometry/Terrain.h"
#include "image/ImageIo.h"
#include "support/TestSupport.h"

using namespace pyrolume;
using namespace pyrolume::geometry;

namespace {
const std::filesystem::path kDir = std::filesystem::path(PYROLUME_SOURCE_DIR) / "assets/terrain";
}

TEST(Terrain, CommittedAssetsAreWhatTheGeneratorWrites) {
  const TerrainParams params;  // the defaults are what assets/terrain holds
  EXPECT_EQ(test::read_file(kDir / "mountain.obj"), terrain_obj(params))
      << "assets/terrain/mountain.obj is stale: rerun gen_terrain (docs/surfaces.md)";
  const Image generated = terrain_albedo(params);
  const Image stored = read_image(kDir / "rock.png");
  ASSERT_EQ(stored.width, generated.width);
  ASSERT_EQ(stored.height, generated.height);
  size_t differ = 0;
  for (size_t i = 0; i < stored.rgb.size(); ++i)
    if (srgb_encode_u8(stored.rgb[i]) != srgb_encode_u8(generated.rgb[i])) ++differ;
  EXPECT_EQ(differ, 0u) << "assets/terrain/rock.png is stale: rerun gen_terrain";
  // Deterministic: a second run gives the same text; another seed does not.
  EXPECT_EQ(terrain_obj(params), terrain_obj(params));
  TerrainParams other = params;
  other.seed = 8;
  EXPECT_NE(terrain_obj(other), terrain_obj(params));
}

TEST(Terrain, AlbedoHasNoRed) {
  const Image img = read_image(kDir / "rock.png");
  ASSERT_GT(img.width, 0);
  float worst = 0.0f;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const float r = img.at(x, y, 0), g = img.at(x, y, 1);
      ASSERT_GT(g, 0.0f);
      worst = std::max(worst, r / g);
      ASSERT_LE(r, 0.5f * g) << "texel " << x << "," << y;
    }
  EXPECT_GT(worst, 0.2f) << "not a plain green image either";
}

TEST(Terrain, MeshSizeShapeAndNormals) {
  const auto obj = kDir / "mountain.obj", png = kDir / "rock.png";
  EXPECT_LT(std::filesystem::file_size(obj) + std::filesystem::file_size(png), 1536u * 1024u);
  const Mesh m = load_obj(obj);
  const TerrainParams p;
  ASSERT_EQ(m.positions.size(), size_t(p.grid) * size_t(p.grid));
  ASSERT_EQ(m.triangles.size(), 2u * size_t(p.grid - 1) * size_t(p.grid - 1));
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const glm::vec3& q : m.positions) {
    lo = glm::min(lo, q);
    hi = glm::max(hi, q);
  }
  EXPECT_FLOAT_EQ(lo.x, -10.0f);
  EXPECT_FLOAT_EQ(hi.x, 10.0f);
  EXPECT_FLOAT_EQ(lo.z, -10.0f);
  EXPECT_FLOAT_EQ(hi.z, 10.0f);
  EXPECT_NEAR(hi.y, 5.0f, 1e-4f);
  EXPECT_GE(lo.y, 0.0f);
  EXPECT_LT(lo.y, 0.2f);
  // The peak is near the centre; the rim is low.
  float rim = 0.0f;
  for (const glm::vec3& q : m.positions)
    if (std::max(std::fabs(q.x), std::fabs(q.z)) >= 9.99f) rim = std::max(rim, q.y);
  EXPECT_LT(rim, 0.5f);
  // Faces wind counter-clockwise seen from above and agree with the vertex normals.
  for (const auto& tri : m.triangles) {
    const glm::vec3 a = m.positions[tri[0].position], b = m.positions[tri[1].position],
                    c = m.positions[tri[2].position];
    const glm::vec3 ng = glm::normalize(glm::cross(b - a, c - a));
    ASSERT_GT(ng.y, 0.0f);
    for (const auto& corner : tri) {
      ASSERT_NE(corner.normal, kNoIndex);
      ASSERT_NE(corner.uv, kNoIndex);
      ASSERT_GT(glm::dot(m.normals[corner.normal], ng), 0.0f);  // same side
      const glm::vec2 uv = m.uvs[corner.uv];
      const glm::vec3 q = m.positions[corner.position];
      // uv = (x, z) mapped onto [0, 1]: the texture's top row is the +z edge.
      ASSERT_NEAR(uv.x, (q.x + 10.0f) / 20.0f, 1e-4f);
      ASSERT_NEAR(uv.y, (q.z + 10.0f) / 20.0f, 1e-4f);
    }
  }
}
