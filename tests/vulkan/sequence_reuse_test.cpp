// Per-sequence work is done once: a VulkanRenderer with frame reuse keeps its
// session (pipeline, BVH, environment) and reloads only the grids per frame,
// and the frames it renders are bit-identical to fresh renders of each frame.
// Likewise a live edit (the preview's): RenderSession::update re-packs only
// the media's headers and renders what a fresh session of the edited scene does.
#include <gtest/gtest.h>

#include <filesystem>

#include "render/vulkan/Context.h"
#include "render/vulkan/RenderSession.h"
#include "render/vulkan/VulkanRenderer.h"
#include "scene/Scene.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"

using namespace pyrolume;
using namespace pyrolume::test;
namespace fs = std::filesystem;

namespace {

RenderResult render_frame(VulkanRenderer& r, const Scene& pattern, int frame) {
  Scene s = scene_at_frame(pattern, frame);
  RenderSettings settings;
  settings.width = 18;
  settings.height = 12;
  settings.spp = 4;
  settings.seed = 9;
  settings.frame = uint32_t(frame);
  return r.render(s, settings, {});
}

BackendOptions validated() {
  BackendOptions o;
  o.validation = true;
  return o;
}

}  // namespace

TEST(SequenceReuse, KeptSessionRendersEachFrameAsAFreshOneDoes) {
  fs::path dir = temp_dir("seq-reuse");
  for (int f = 1; f <= 3; ++f) {
    Lattice l;
    l.voxel = 0.1 + 0.01 * f;  // a different lattice and size every frame
    char name[32];
    std::snprintf(name, sizeof name, "g_%04d.vdb", f);
    write_explosion_shell_vdb(dir / name, l, 2.0 + f, 5.0 + 1.5 * f, 1.5f, 1800.0f + 400.0f * f, 600.0f);
  }
  // A sphere surface too: its BVH is what the kept session must not rebuild.
  write_file(dir / "s.json", R"({
    "camera": {"position": {"keys": [[1, [0, 0.5, -4]], [3, [0.8, 0.5, -3.6]]]}, "look_at": [0, 0, 0]},
    "background": {"rgb": [0.2, 0.2, 0.25]},
    "integrator": {"mis": false},
    "media": [{"type": "vdb", "file": "g_####.vdb", "sigma_a": [1, 1, 1], "sigma_s": [1, 1, 1],
               "emission": {"scale": {"keys": [[1, 1], [3, 3]]}}}],
    "shapes": [{"sphere": {"center": [0, -11, 0], "radius": 10}}]
  })");
  const Scene pattern = load_scene(dir / "s.json");

  VulkanRenderer seq(validated());
  seq.set_frame_reuse(true);
  std::vector<RenderResult> in_sequence;
  for (int f = 1; f <= 3; ++f) in_sequence.push_back(render_frame(seq, pattern, f));
  EXPECT_EQ(seq.reused_frames(), 2);
  EXPECT_EQ(seq.validation_messages(), 0u);

  for (int f = 3; f >= 1; --f) {
    VulkanRenderer alone(validated());
    RenderResult r = render_frame(alone, pattern, f);
    EXPECT_EQ(alone.reused_frames(), 0);
    EXPECT_EQ(r.sum, in_sequence[size_t(f - 1)].sum) << "frame " << f;
    EXPECT_EQ(r.sum_sq, in_sequence[size_t(f - 1)].sum_sq) << "frame " << f;
    EXPECT_EQ(alone.validation_messages(), 0u);
  }
  // Frames must really differ, or the comparison above proves nothing.
  EXPECT_NE(in_sequence[0].sum, in_sequence[2].sum);

  // Another image size cannot reuse the session: a new one is built.
  Scene s = scene_at_frame(pattern, 2);
  RenderSettings other;
  other.width = 10;
  other.height = 10;
  other.spp = 1;
  other.frame = 2;
  RenderResult small = seq.render(s, other, {});
  EXPECT_EQ(small.width, 10);
  EXPECT_EQ(seq.reused_frames(), 2);
}

// The preview's temperature edit ([ and ]): the session keeps its majorant
// cells and blackbody LUT, and its render equals a fresh session's.
TEST(SessionEdit, TemperatureEditRendersAsAFreshSessionDoes) {
  fs::path dir = temp_dir("session-edit");
  write_explosion_shell_vdb(dir / "g.vdb", Lattice{}, 3.0, 7.0, 1.5f, 2200.0f, 600.0f);
  write_file(dir / "s.json", R"({
    "camera": {"position": [0, 0.3, -3], "look_at": [0, 0, 0]},
    "integrator": {"majorant_grid": [3, 2, 2]},
    "media": [{"type": "vdb", "file": "g.vdb", "sigma_a": [1, 1, 1], "sigma_s": [2, 2, 2],
               "emission": {"scale": 1}}]
  })");
  const Scene scene = load_scene(dir / "s.json");
  Scene edited = scene;
  edited.media[0].temperature.scale *= 1.25;
  RenderSettings settings;
  settings.width = 16;
  settings.height = 12;
  settings.seed = 3;
  vk::Context::Options o;
  o.validation = true;
  vk::Context ctx(o);
  const uint64_t before = vk::Context::total_validation_messages();
  auto render = [](RenderSession& s) {
    EXPECT_TRUE(s.run_pass(4));
    RenderResult r;
    s.read(r);
    return r;
  };
  RenderSession kept(ctx, scene, settings);
  const RenderResult original = render(kept);
  kept.update(edited);
  const RenderResult after_edit = render(kept);
  RenderSession fresh(ctx, edited, settings);
  const RenderResult expected = render(fresh);
  EXPECT_EQ(after_edit.sum, expected.sum);
  EXPECT_EQ(after_edit.sum_sq, expected.sum_sq);
  EXPECT_NE(after_edit.sum, original.sum);  // the edit changed the image
  EXPECT_EQ(vk::Context::total_validation_messages(), before);
}
