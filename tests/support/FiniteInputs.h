#pragma once
// Inputs with values beyond what the renderers can carry, and the checks on
// them (docs/robustness.md "Finite by construction"), written once and run
// per backend: tests/unit/cli_finite_inputs_test.cpp (CPU) and
// tests/vulkan/cli_finite_inputs_vulkan_test.cpp (Vulkan; Vulkan renders stay
// out of the `unit` label, which tools/sanitize runs: lavapipe's JIT and
// ASan's slow unwinder deadlock). 8×8 at 1-4 spp.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>

#include <nlohmann/json.hpp>

#include "image/ImageIo.h"
#include "support/AccumulationChecks.h"
#include "support/VdbScenes.h"

namespace pyrolume::test {

inline const char* kFiniteFilm =
    R"("film": {"width": 8, "height": 8, "spp": 1}, "camera": {"position": [0, 1, -6], "look_at": [0, 1, 0]})";

// The files the scenes below read, written into `dir`.
inline void write_finite_inputs(const std::filesystem::path& dir) {
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
  write_vdb(dir / "ball.vdb", {make_float_grid("density", Lattice{0.25, {-1, 0, -1}}, VoxelBox{{0, 0, 0}, {7, 7, 7}},
                                               [](int, int, int) { return 1.0f; })});
  // The same ball with a 3000 K temperature grid: a grid's emission is
  // checked against its hottest voxel once loaded.
  write_vdb(dir / "hot_ball.vdb", {make_float_grid("density", Lattice{0.25, {-1, 0, -1}}, VoxelBox{{0, 0, 0}, {7, 7, 7}},
                                                   [](int, int, int) { return 1.0f; }),
                                   make_float_grid("temperature", Lattice{0.25, {-1, 0, -1}}, VoxelBox{{0, 0, 0}, {7, 7, 7}},
                                                   [](int, int, int) { return 3000.0f; })});
}

struct FiniteCase {
  std::string label, scene, expect;
  // Refused by code both backends share (the scene loader, or a check in
  // check_scene_ranges whose Vulkan call another case covers): checked on the
  // CPU only, since each lavapipe run costs a process start.
  bool cpu_only = false;
};

// Each refused at load, exit 2, one line naming the file and the key (`expect`
// after the folder prefix when it starts with '/').
inline std::vector<FiniteCase> refused_finite_cases(const std::filesystem::path& dir) {
  const std::string d = dir.string() + "/";
  return {
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
       R"("media": [{"type": "vdb", "file": "hot_ball.vdb", "source": "kelvin",
                     "emission": {"scale": 1e30, "blackbody": "physical"}}])",
       "media[0].emission.scale: emission.scale 1e+30 × the brightest physical blackbody colour up to the grid's hottest voxel, 3000 K"},
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
      // Analytic lights: values within the media's emission bound, the
      // blackbody range, coordinates float keeps finite, a bounded count.
      {"point intensity 1e38", R"("lights": [{"type": "point", "position": [0, 2, 0], "intensity": [1e38, 1, 1]}])",
       "lights[0].intensity: scale 1 × intensity (1e+38) gives 1e+38, beyond 1e+12"},
      {"distant irradiance 1e38", R"("lights": [{"type": "distant", "direction": [0, 1, 0], "irradiance": [1e38, 1e38, 1e38]}])",
       "lights[0].irradiance: scale 1 × irradiance (1e+38)", true},
      {"sphere radiance 1e38", R"("lights": [{"type": "sphere", "center": [0, 3, 0], "radius": 1, "radiance": [0, 0, 1e38]}])",
       "lights[0].radiance: scale 1 × radiance (1e+38)", true},
      {"temperature_k with scale 1e38", R"("lights": [{"type": "spot", "position": [0, 2, 0], "direction": [0, -1, 0],
                                                      "temperature_k": 3000, "scale": 1e38}])",
       "lights[0].scale: scale 1e+38 × the luminance-1 colour of temperature_k", true},
      {"disc sun brighter than the bound", R"("lights": [{"type": "distant", "direction": [0, 1, 0], "irradiance": [1e6, 1e6, 1e6],
                                                        "angle_deg": 0.001}])",
       "lights[0].angle_deg: the disc's radiance, irradiance / (π sin²(angle_deg/2)), is 4.18e+15, beyond 1e+12"},
      {"light at 10 K", R"("lights": [{"type": "point", "position": [0, 2, 0], "temperature_k": 10}])",
       "lights[0].temperature_k: must be in [100.0, 1000000.0] kelvin", true},
      {"light at 1e300 K", R"("lights": [{"type": "point", "position": [0, 2, 0], "temperature_k": 1e300}])",
       "lights[0].temperature_k: must be in [100.0, 1000000.0] kelvin", true},
      {"sphere light radius 1e300", R"("lights": [{"type": "sphere", "center": [0, 3, 0], "radius": 1e300, "radiance": [1, 1, 1]}])",
       "lights[0].radius: the sphere's extent", true},
      {"too many lights", [] {
         std::string l = R"("lights": [)";
         for (size_t k = 0; k <= kMaxLights; ++k)
           l += std::string(k ? ", " : "") + R"({"type": "point", "position": [0, 2, 0], "intensity": [1, 1, 1]})";
         return l + "]";
       }(),
       "s.json: lights: " + std::to_string(kMaxLights + 1) + " lights, more than the " + std::to_string(kMaxLights), true},
  };
}

inline void expect_finite_case_refused(const std::filesystem::path& dir, const FiniteCase& c, const std::string& backend) {
  write_file(dir / "s.json", "{" + std::string(kFiniteFilm) + ", " + c.scene + "}");
  CliResult r = run_cli("render " + q(dir / "s.json") + " -o " + q(dir / "o.exr") + " --backend " + backend);
  EXPECT_EQ(r.status, 2) << c.label << " (" << backend << "): " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.label << ": " << r.err;
  EXPECT_NE(r.err.find(c.expect), std::string::npos) << c.label << " (" << backend << "): expected '" << c.expect
                                                     << "' in " << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "o.exr")) << c.label;
}

// Every case of refused_finite_cases on one backend.
inline void expect_finite_cases_refused(const std::string& backend) {
  const auto dir = temp_dir("finite-refused-" + backend);
  write_finite_inputs(dir);
  for (const FiniteCase& c : refused_finite_cases(dir))
    if (!c.cpu_only || backend == "cpu") expect_finite_case_refused(dir, c, backend);
  std::filesystem::remove_all(dir);
}

// A 65536 × 1 albedo texture (wider than any GPU's 2D texture side) on a
// plane: what rendering it with `backend` says. The folder is removed.
inline CliResult render_wide_texture(const std::string& backend) {
  const auto dir = temp_dir("finite-wide-" + backend);
  write_image(dir / "wide.png", make_image(65536, 1));
  write_file(dir / "w.json", "{" + std::string(kFiniteFilm) + R"(, "shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 1, 0]},
                "material": {"diffuse": {"texture": "wide.png"}}}]})");
  CliResult r = run_cli("render " + q(dir / "w.json") + " -o " + q(dir / "o.exr") + " --backend " + backend);
  if (r.status != 0) EXPECT_FALSE(std::filesystem::exists(dir / "o.exr")) << "a refusal wrote the image";
  std::filesystem::remove_all(dir);
  return r;
}

// A plane whose normal's length overflows (its direction does not) renders:
// finite, and the grey plane is seen against the white sky.
inline void expect_overflowing_plane_normal_renders(const std::string& backend) {
  const auto dir = temp_dir("finite-plane-" + backend);
  write_file(dir / "p.json", "{" + std::string(kFiniteFilm) + R"(, "background": {"rgb": [1, 1, 1]},
    "shapes": [{"plane": {"center": [0, 0, 0], "normal": [1e300, 1e300, 0]},
                "material": {"diffuse": {"rgb": [0.5, 0.5, 0.5]}}}]})");
  CliResult r = run_cli("render " + q(dir / "p.json") + " -o " + q(dir / "p.exr") + " --backend " + backend);
  ASSERT_EQ(r.status, 0) << backend << ": " << r.err;
  const Image img = read_image(dir / "p.exr");
  size_t plane = 0;  // values darker than the white sky
  for (float v : img.rgb) {
    ASSERT_TRUE(std::isfinite(v)) << backend;
    plane += v < 0.9f;
  }
  EXPECT_GT(plane, 0u) << backend;
  EXPECT_LT(plane, img.rgb.size()) << backend;
  std::filesystem::remove_all(dir);
}

// Analytic lights at the largest values the scene format accepts, over a grey
// plane seen from above: they render finite, with no sample beyond
// gpu::MAX_SAMPLE_RADIANCE, and light the plane (the image's mean at least
// `min_mean`: a plane of albedo 0.5 at irradiance E shows 0.5 E / π, and each
// bound is a tenth of that). Two scenes, since each lavapipe render compiles
// its pipeline: every type at its largest value together, and alone the
// direction whose length overflows (that light used to vanish).
struct ExtremeLights {
  std::string label, lights;
  double min_mean;
};
inline std::vector<ExtremeLights> extreme_lights() {
  return {
      {"every type at its largest value",
       R"({"type": "point", "position": [0, 3, 0], "intensity": [1e12, 1e12, 1e12]},
          {"type": "spot", "position": [0, 3, 0], "direction": [0, -1e-300, 0], "cone_deg": 60,
           "intensity": [1e12, 1e12, 1e12]},
          {"type": "distant", "direction": [0, 1, 0], "angle_deg": 20, "irradiance": [9e10, 9e10, 9e10]},
          {"type": "sphere", "center": [0, 6e17, 0], "radius": 4e17, "radiance": [1e12, 1e12, 1e12]},
          {"type": "point", "position": [0, 1e18, 0], "intensity": [1e12, 1e12, 1e12]},
          {"type": "point", "position": [1, 3, 0], "temperature_k": 1e6, "scale": 4.4e11},
          {"type": "point", "position": [-1, 3, 0], "temperature_k": 100, "scale": 2e11})",
       1e10},
      {"distant, irradiance 1e12 along [1e200, 1e200, 0]",
       R"({"type": "distant", "direction": [1e200, 1e200, 0], "irradiance": [1e12, 1e12, 1e12]})", 1e10},
  };
}

inline void expect_extreme_lights_render_finite(const std::string& backend) {
  const auto dir = temp_dir("finite-lights-" + backend);
  for (const ExtremeLights& l : extreme_lights()) {
    write_file(dir / "l.json", R"({"film": {"width": 8, "height": 8, "spp": 2},
      "camera": {"position": [0, 4, -1], "look_at": [0, 0, 0], "fov_deg": 60},
      "shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 1, 0]}, "material": {"diffuse": {"rgb": [0.5, 0.5, 0.5]}}}],
      "lights": [)" + l.lights + "]}");
    std::filesystem::remove(dir / "l.exr");
    const CliResult r = run_cli("render " + q(dir / "l.json") + " -o " + q(dir / "l.exr") + " --backend " + backend +
                                " --stats " + q(dir / "st.json"));
    ASSERT_EQ(r.status, 0) << l.label << " (" << backend << "): " << r.err;
    const auto stats = nlohmann::json::parse(read_file(dir / "st.json"));
    EXPECT_EQ(stats["nonfinite_samples"].get<uint64_t>(), 0u) << l.label << " (" << backend << ")";
    const Image img = read_image(dir / "l.exr");
    double sum = 0.0;
    for (float v : img.rgb) {
      ASSERT_TRUE(std::isfinite(v)) << l.label << " (" << backend << ")";
      sum += v;
    }
    const double mean = sum / double(img.rgb.size());
    std::printf("%s (%s): mean %.3g\n", l.label.c_str(), backend.c_str(), mean);
    EXPECT_GE(mean, l.min_mean) << l.label << " (" << backend << "): the light vanished";
  }
  std::filesystem::remove_all(dir);
}

// An albedo texture of 1e20 (finite, accepted) under a white sky: a path that
// bounces off it carries ~1e20, past gpu::MAX_SAMPLE_RADIANCE, where 2^24
// float squares could overflow. Such samples are recorded as 0 and counted;
// the EXR (mean and variance) stays finite.
inline void expect_samples_beyond_the_bound_counted(const std::string& backend) {
  const auto dir = temp_dir("finite-bound-" + backend);
  Image tex = make_image(2, 2);
  for (float& v : tex.rgb) v = 1e20f;
  write_image(dir / "huge.exr", tex);
  write_file(dir / "h.json", R"({"film": {"width": 8, "height": 8, "spp": 4},
    "camera": {"position": [0, 1, -6], "look_at": [0, 0, 0]},
    "integrator": {"mis": false, "max_depth": 1}, "background": {"rgb": [1, 1, 1]},
    "shapes": [{"plane": {"center": [0, 0, 0], "normal": [0, 1, 0]},
                "material": {"diffuse": {"texture": "huge.exr"}}}]})");
  CliResult r = run_cli("render " + q(dir / "h.json") + " -o " + q(dir / "h.exr") + " --backend " + backend +
                        " --variance --stats " + q(dir / "st.json"));
  ASSERT_EQ(r.status, 0) << backend << ": " << r.err;
  const auto stats = nlohmann::json::parse(read_file(dir / "st.json"));
  EXPECT_GT(stats["nonfinite_samples"].get<uint64_t>(), 0u) << backend;
  EXPECT_NE(r.err.find("non-finite samples were recorded as 0"), std::string::npos) << r.err;
  const Image img = read_image(dir / "h.exr");
  for (size_t i = 0; i < img.rgb.size(); ++i) {
    ASSERT_TRUE(std::isfinite(img.rgb[i])) << backend << " value " << i;
    ASSERT_LE(img.rgb[i], 1.0f) << backend << ": a huge sample was accumulated";
    ASSERT_TRUE(std::isfinite(img.variance[i])) << backend << " variance " << i;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace pyrolume::test
