// Keyframed scene parameters ({"keys": [[frame, value], ...]}), frame patterns
// in file names, and --frames ranges (docs/animation.md).
#include <gtest/gtest.h>

#include "cli/Sequence.h"
#include "scene/Scene.h"
#include "util/Error.h"

using namespace pyrolume;

namespace {

Scene parse(const std::string& text) { return parse_scene(text, "/scenes/anim.json"); }

// The InputError message of parsing `text`, or "" when it parses.
std::string parse_error(const std::string& text) {
  try {
    parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

const char* kAnimated = R"({
  "camera": {"position": {"keys": [[1, [0, 0, -10]], [11, [10, 0, -10]], [21, [10, 5, -10]]]},
             "look_at": {"keys": [[1, [0, 0, 0]], [21, [0, 2, 0]]]}},
  "film": {"exposure": {"keys": [[0, -1], [10, 1]]}},
  "media": [{"type": "vdb", "file": "fire_####.vdb", "emission": {"scale": {"keys": [[5, 2], [15, 0]]}}},
            {"type": "vdb", "file": "smoke_$F3.vdb"},
            {"type": "homogeneous", "bounds": {"sphere": {"center": [0, 0, 0], "radius": 1}},
             "emission": {"rgb": [1, 1, 1], "scale": 3}}]
})";

}  // namespace

TEST(AnimationKeyframes, ExactAtKeysLinearBetweenClampedOutside) {
  Scene s = parse(kAnimated);
  ASSERT_TRUE(scene_is_animated(s));
  // At the keys: exactly the key values.
  EXPECT_EQ(scene_at_frame(s, 1).camera.position, glm::dvec3(0, 0, -10));
  EXPECT_EQ(scene_at_frame(s, 11).camera.position, glm::dvec3(10, 0, -10));
  EXPECT_EQ(scene_at_frame(s, 21).camera.position, glm::dvec3(10, 5, -10));
  EXPECT_EQ(scene_at_frame(s, 10).film.exposure, 1.0);
  // Between keys: linear, per segment.
  glm::dvec3 p6 = scene_at_frame(s, 6).camera.position;
  EXPECT_DOUBLE_EQ(p6.x, 5.0);
  EXPECT_DOUBLE_EQ(p6.y, 0.0);
  glm::dvec3 p16 = scene_at_frame(s, 16).camera.position;
  EXPECT_DOUBLE_EQ(p16.x, 10.0);
  EXPECT_DOUBLE_EQ(p16.y, 2.5);
  EXPECT_DOUBLE_EQ(scene_at_frame(s, 11).camera.look_at.y, 1.0);
  EXPECT_DOUBLE_EQ(scene_at_frame(s, 5).film.exposure, 0.0);
  EXPECT_DOUBLE_EQ(scene_at_frame(s, 7).media[0].emission.scale, 2.0 - 2.0 * 0.2);
  // Outside the key range: held at the first / last key.
  EXPECT_EQ(scene_at_frame(s, 0).camera.position, glm::dvec3(0, 0, -10));
  EXPECT_EQ(scene_at_frame(s, 500).camera.position, glm::dvec3(10, 5, -10));
  EXPECT_EQ(scene_at_frame(s, 0).media[0].emission.scale, 2.0);
  EXPECT_EQ(scene_at_frame(s, 99).media[0].emission.scale, 0.0);
  // Unkeyed values stay as written.
  EXPECT_EQ(scene_at_frame(s, 7).media[2].emission.scale, 3.0);
  // Parsing stores the values at frame 0 (a render without --frames).
  EXPECT_EQ(s.camera.position, glm::dvec3(0, 0, -10));
  EXPECT_EQ(s.film.exposure, -1.0);
  EXPECT_EQ(s.media[0].emission.scale, 2.0);
}

TEST(AnimationKeyframes, FractionalFramesInterpolate) {
  Keyframes<double> k{{0.0, 4.0}, {0.0, 8.0}};
  EXPECT_DOUBLE_EQ(k.at(1.0), 2.0);
  EXPECT_DOUBLE_EQ(k.at(-3.0), 0.0);
  EXPECT_DOUBLE_EQ(k.at(9.0), 8.0);
  Keyframes<double> one{{3.0}, {7.0}};
  EXPECT_EQ(one.at(-100.0), 7.0);
  EXPECT_EQ(one.at(100.0), 7.0);
}

TEST(AnimationKeyframes, PatternsExpandPerFrame) {
  Scene s = parse(kAnimated);
  EXPECT_TRUE(scene_has_file_patterns(s));
  Scene f7 = scene_at_frame(s, 7);
  EXPECT_EQ(f7.media[0].file, std::filesystem::path("/scenes/fire_0007.vdb"));
  EXPECT_EQ(f7.media[1].file, std::filesystem::path("/scenes/smoke_007.vdb"));
  // The pattern scene is unchanged: it can be evaluated at any frame again.
  EXPECT_EQ(scene_at_frame(s, 123).media[0].file, std::filesystem::path("/scenes/fire_0123.vdb"));

  EXPECT_EQ(expand_frame_pattern("out_####.exr", 12), "out_0012.exr");
  EXPECT_EQ(expand_frame_pattern("out_#.exr", 12), "out_12.exr");  // never truncated
  EXPECT_EQ(expand_frame_pattern("a_$F4_b_$F.vdb", 7), "a_0007_b_7.vdb");
  EXPECT_EQ(expand_frame_pattern("d##/f###.png", 5), "d05/f005.png");
  EXPECT_EQ(expand_frame_pattern("plain.exr", 5), "plain.exr");
  EXPECT_TRUE(has_frame_pattern("x_$F.exr"));
  EXPECT_TRUE(has_frame_pattern("x_#.exr"));
  EXPECT_FALSE(has_frame_pattern("x_F4.exr"));
  EXPECT_FALSE(scene_is_animated(parse(R"({"camera": {"position": [0, 0, -3]}})")));
}

TEST(AnimationKeyframes, BadKeysNameTheKey) {
  auto expect_error = [](const std::string& text, const std::string& key, const std::string& reason) {
    std::string e = parse_error(text);
    EXPECT_NE(e.find(key), std::string::npos) << "message: " << e;
    EXPECT_NE(e.find(reason), std::string::npos) << "message: " << e;
  };
  expect_error(R"({"camera": {"position": {"keys": [[5, [0, 0, -5]], [2, [1, 0, -5]]]}}})",
               "camera.position.keys[1]", "increase");
  expect_error(R"({"camera": {"position": {"keys": [[1, [0, 0, -5]], [1, [1, 0, -5]]]}}})",
               "camera.position.keys[1]", "increase");
  expect_error(R"({"camera": {"look_at": {"keys": [[1, [0, 0, 0]], [2, 3]]}}})", "camera.look_at.keys[1]",
               "[x, y, z]");
  expect_error(R"({"film": {"exposure": {"keys": [[1, 0], [2, [1, 2, 3]]]}}})", "film.exposure.keys[1]",
               "expected a number");
  expect_error(R"({"film": {"exposure": {"keys": []}}})", "film.exposure.keys", "non-empty");
  expect_error(R"({"film": {"exposure": {"keys": [[1]]}}})", "film.exposure.keys[0]", "[frame, value]");
  expect_error(R"({"film": {"exposure": {"keys": [["a", 1]]}}})", "film.exposure.keys[0]", "frame");
  expect_error(R"({"film": {"exposure": {"kees": [[1, 1]]}}})", "film.exposure", "keys");
  expect_error(R"({"film": {"exposure": {"keys": [[1, 1]], "mode": "linear"}}})", "film.exposure.mode",
               "unknown key");
  expect_error(R"({"media": [{"type": "vdb", "file": "f.vdb", "emission": {"scale": {"keys": [[1, 1], [2, -1]]}}}]})",
               "media[0].emission.scale.keys[1]", ">= 0");
  // Keys may not be given where the format has no animation.
  expect_error(R"({"camera": {"fov_deg": {"keys": [[1, 30]]}}})", "camera.fov_deg", "expected a number");
}

TEST(AnimationKeyframes, CameraBrokenByKeysNamesTheFrame) {
  Scene s = parse(R"({"camera": {"position": {"keys": [[0, [0, 0, -5]], [10, [0, 0, 5]]]},
                                 "look_at": [0, 0, 0]}})");
  try {
    scene_at_frame(s, 5);
    FAIL() << "expected an error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("camera.look_at"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("frame 5"), std::string::npos) << e.what();
  }
}

TEST(AnimationFrameRange, ParsesAndRejects) {
  FrameRange r = parse_frame_range("1-120");
  EXPECT_EQ(r.first, 1);
  EXPECT_EQ(r.last, 120);
  EXPECT_EQ(r.count(), 120u);
  auto frames = [](const FrameRange& range) {
    std::vector<int> v;
    for (int f : range) v.push_back(f);
    EXPECT_EQ(v.size(), range.count());
    return v;
  };
  EXPECT_EQ(frames(r).size(), 120u);
  EXPECT_EQ(frames(parse_frame_range("1-10:4")), (std::vector<int>{1, 5, 9}));
  EXPECT_EQ(frames(parse_frame_range("1-9:4")), (std::vector<int>{1, 5, 9}));
  EXPECT_EQ(frames(parse_frame_range("7")), (std::vector<int>{7}));
  EXPECT_EQ(frames(parse_frame_range("0-0")), (std::vector<int>{0}));
  // The widest range: counted, not listed (it used to build a 4 GB vector
  // before frame 0), and the last frame's successor does not overflow.
  const FrameRange huge = parse_frame_range("0-999999999");
  EXPECT_EQ(huge.count(), 1000000000u);
  EXPECT_EQ(*huge.begin(), 0);
  const FrameRange top = parse_frame_range("999999998-999999999:7");
  EXPECT_EQ(frames(top), (std::vector<int>{999999998}));
  for (const char* bad : {"", "a-b", "5-1", "1-5:0", "1-5:", "-3", "1-", "1-5:x", "1--5", "1.5-3"}) {
    try {
      parse_frame_range(bad);
      ADD_FAILURE() << "accepted \"" << bad << "\"";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--frames"), std::string::npos) << e.what();
    }
  }
}
