// Values beyond what the renderers can carry are refused at load (exit 2, one
// line naming the file and the key) or rendered finite (docs/robustness.md
// "Finite by construction"). Each case once per backend; 8×8 at 1-4 spp.
#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

#include "image/ImageIo.h"
#include "support/AccumulationChecks.h"
#include "support/VdbScenes.h"

namespace pyrolume {
namespace {
using namespace pyrolume::test;
namespace fs = std::filesystem;

const char* kFilm = R"("film": {"width": 8, "height": 8, "spp": 1}, "camera": {"position": [0, 1, -6], "look_at": [0, 1, 0]})";

// The files the scenes below read, written once per test into `dir`.
void write_inputs(const fs::path& dir) {
  write_file(dir / "tri.obj", "v -1 0 0\nv 1 0 0\nv 0 2 0\nf 1 2 3\n");
  for (const auto& [name, text] :
       {std::pair<std::string, std::string>{"nan.obj", "v -1 0 0\nv nan 0 0\nv 0 2 0\nf 1 2 3\n"},
        {"inf.obj", "v -1 0 0\nv 1 0 0\nv 0 -inf 0\nf 1 2 3\n"},
        {"big.obj", "v -1 0 0\nv 1 0 0\nv 0 1e39 0\nf 1 2 3\n"},
        {"nanuv.obj", "v -1 0 0\nv 1 0 0\nv 0 2 0\nvt 0 0\nvt nan 0\nvt 0 1\nf 1/1 2/2 3/3\n"}})
    write_file(dir / name, text);
  Image sky = make_image(4, 2);
  for (float& v : sky.rgb) v = 3e38f;  // finite, but no float sum survives it
  write_image(dir / "bright_sky.exr", sky);
  sky.rgb[5] = std::nanf("");
  write_image(dir / "nan_sky.exr", sky);
  Image tex = make_image(2, 2);
  for (float& v : tex.rgb) v = 0.5f;
  tex.rgb[4] = std::numeric_limits<float>::infinity();
  write_image(dir / "inf_tex.exr", tex);
  write_image(dir / "wide.png", make_image(65536, 1));
  write_vdb(dir / "ball.vdb", {make_float_grid("density", Lattice{0.25, {-1, 0, -1}}, VoxelBox{{0, 0, 0}, {7, 7, 7}},
                                               [](int, int, int) { return 1.0f; })});
}

struct Case {
  std::string label, scene, expect;
};

// Refused: exit 2 on both backends, one line, no output.
void expect_refused(const fs::path& dir, const Case& c) {
  write_file(dir / "s.json", "{" + std::string(kFilm) + ", " + c.scene + "}");
  for (const char* backend : {"cpu", "vulkan"}) {
    CliResult r = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --backend " + backend);
    EXPECT_EQ(r.status, 2) << c.label << " (" << backend << "): " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.label << ": " << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.label << " (" << backend << "): expected '" << c.expect
                                                       << "' in " << r.err;
    EXPECT_FALSE(fs::exists(dir / "o.exr")) << c.label;
  }
}

TEST(CliFiniteInputs, ValuesBeyondFloatAreRefusedNamingTheKey) {
  auto dir = temp_dir("finite-refused");
  write_inputs(dir);
  const std::string d = dir.string() + "/";
  const Case cases[] = {
      {"NaN vertex", R"("shapes": [{"mesh": "nan.obj"}])", d + "nan.obj: line 2: \"nan\" is not a finite number"},
      {"-Inf vertex", R"("shapes": [{"mesh": "inf.obj"}])", d + "inf.obj: line 3: \"-inf\" is not a finite number"},
      {"vertex beyond float", R"("shapes": [{"mesh": "big.obj"}])", d + "big.obj: line 3: \"1e39\""},
      {"NaN uv", R"("shapes": [{"mesh": "nanuv.obj"}])", d + "nanuv.obj: line 5: \"nan\""},
      {"mesh scaled by 1e300", R"("shapes": [{"mesh": "tri.obj", "transform": {"scale": [1e300, 1e300, 1e300]}}])",
       "shapes[0].transform: vertex 1 of"},
      {"sphere beyond float", R"("shapes": [{"sphere": {"center": [0, 0, 0], "radius": 1e300}}])",
       "shapes[0].sphere: the sphere's extent"},
      {"emission.scale 1e38",
       R"("media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0, 1, 0], "radius": 1}},
                     "emission": {"temperature_k": 1500, "scale": 1e38}}])",
       "media[0].emission.scale: emission.scale 1e+38"},
      {"grid emission.scale 1e30 (physical)",
       R"("media": [{"type": "vdb", "file": "ball.vdb", "emission": {"scale": 1e30, "blackbody": "physical"}}])",
       "media[0].emission.scale"},
      {"sigma beyond float", R"("media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0, 1, 0], "radius": 1}},
                                         "sigma_a": [1e35, 1, 1]}])",
       "media[0].sigma_a: σa + σs reaches 1e+35"},
      {"density_scale 1e20", R"("media": [{"type": "vdb", "file": "ball.vdb", "density_scale": 1e20}])",
       "media[0].density_scale: the grid's majorant optical depth is"},
      {"grid transform scale 1e-300", R"("media": [{"type": "vdb", "file": "ball.vdb",
                                                   "transform": {"scale": [1e-300, 1e-300, 1e-300]}}])",
       d + "ball.vdb: density grid \"density\": its index-to-world map"},
      {"environment texels of 3e38", R"("environment": {"file": "bright_sky.exr"})",
       d + "bright_sky.exr: texels up to 3e+38 times environment.scale 1"},
      {"environment with a NaN texel", R"("environment": {"file": "nan_sky.exr"})",
       d + "nan_sky.exr: 1 texel values are NaN or infinite"},
      {"texture with an Inf texel", R"("shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 1, 0]},
                                                  "material": {"diffuse": {"texture": "inf_tex.exr"}}}])",
       d + "inf_tex.exr: 1 texel values are NaN or infinite (the first at x 1, y 0)"},
      {"duplicate key", R"("media": [], "shapes": [], "media": [])", "s.json: media: duplicate key"},
  };
  for (const Case& c : cases) expect_refused(dir, c);
  fs::remove_all(dir);
}

TEST(CliFiniteInputs, ExtremeButRepresentableValuesRenderFinite) {
  auto dir = temp_dir("finite-rendered");
  write_inputs(dir);
  // A plane whose normal's length overflows (its direction does not), and a
  // texture wider than lavapipe's 16384 texels per side: the CPU renders it,
  // the GPU refuses it naming the file (a device limit).
  write_file(dir / "s.json", "{" + std::string(kFilm) + R"(, "background": {"rgb": [1, 1, 1]},
    "shapes": [{"plane": {"center": [0, 0, 0], "normal": [1e300, 1e300, 0]},
                "material": {"diffuse": {"rgb": [0.5, 0.5, 0.5]}}}]})");
  for (const char* backend : {"cpu", "vulkan"}) {
    CliResult r = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --backend " + backend);
    ASSERT_EQ(r.status, 0) << backend << ": " << r.err;
    const Image img = read_image(dir / "o.exr");
    size_t plane = 0;  // values darker than the white sky: the grey plane is seen
    for (float v : img.rgb) {
      ASSERT_TRUE(std::isfinite(v)) << backend;
      plane += v < 0.9f;
    }
    EXPECT_GT(plane, 0u) << backend;
    EXPECT_LT(plane, img.rgb.size()) << backend;
    fs::remove(dir / "o.exr");
  }
  write_file(dir / "w.json", "{" + std::string(kFilm) + R"(, "shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 1, 0]},
                "material": {"diffuse": {"texture": "wide.png"}}}]})");
  CliResult r = run_cli("render " + q(dir / "w.json") + " -o " + q(dir / "o.exr") + " --backend cpu");
  EXPECT_EQ(r.status, 0) << r.err;
  r = run_cli("render " + q(dir / "w.json") + " -o " + q(dir / "v.exr") + " --backend vulkan");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find((dir / "wide.png").string() + ": 65536 x 1 texels exceed this device's 2D texture limit"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "v.exr"));
  fs::remove_all(dir);
}

TEST(CliFiniteInputs, SamplesBeyondTheRadianceBoundAreCountedNotAccumulated) {
  // An albedo texture of 1e20 (finite, accepted) under a white sky: a path
  // that bounces off it carries ~1e20, past gpu::MAX_SAMPLE_RADIANCE, where
  // 2^24 float squares could overflow. Such samples are recorded as 0 and
  // counted; the EXR stays finite on both backends.
  auto dir = temp_dir("finite-bound");
  Image tex = make_image(2, 2);
  for (float& v : tex.rgb) v = 1e20f;
  write_image(dir / "huge.exr", tex);
  write_file(dir / "s.json", R"({"film": {"width": 8, "height": 8, "spp": 4},
    "camera": {"position": [0, 1, -6], "look_at": [0, 0, 0]},
    "integrator": {"mis": false, "max_depth": 1}, "background": {"rgb": [1, 1, 1]},
    "shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 1, 0]},
                "material": {"diffuse": {"texture": "huge.exr"}}}]})");
  for (const char* backend : {"cpu", "vulkan"}) {
    CliResult r = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --backend " + backend +
                          " --variance --stats " + q(dir / "st.json"));
    ASSERT_EQ(r.status, 0) << backend << ": " << r.err;
    const auto stats = nlohmann::json::parse(read_file(dir / "st.json"));
    EXPECT_GT(stats["nonfinite_samples"].get<uint64_t>(), 0u) << backend;
    EXPECT_NE(r.err.find("non-finite samples were recorded as 0"), std::string::npos) << r.err;
    const Image img = read_image(dir / "o.exr");
    for (size_t i = 0; i < img.rgb.size(); ++i) {
      ASSERT_TRUE(std::isfinite(img.rgb[i])) << backend << " value " << i;
      ASSERT_LE(img.rgb[i], 1.0f) << backend << ": a huge sample was accumulated";
      ASSERT_TRUE(std::isfinite(img.variance[i])) << backend << " variance " << i;
    }
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace pyrolume
