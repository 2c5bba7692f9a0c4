// The CLI turns bad input into one line on stderr naming the key, exit status 2,
// and no output file.
#include <gtest/gtest.h>

#include "support/TestSupport.h"

using namespace pyrolume::test;

namespace {
struct CliCase {
  const char* label;
  std::string scene;   // scene text, written to bad.json
  std::string flags;   // extra flags
  const char* expect;  // substring of stderr
};

class CliBadInput : public ::testing::TestWithParam<CliCase> {};

const std::string kSphere = R"({"film": {"width": 8, "height": 8, "spp": 1},
  "media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0,1,0], "radius": 1}}}]})";
}  // namespace

TEST_P(CliBadInput, ExitTwoNoOutput) {
  const CliCase& c = GetParam();
  auto dir = temp_dir("clibad");
  write_file(dir / "bad.json", c.scene);
  auto out = dir / "out.exr";
  for (const char* backend : {"cpu", "vulkan"}) {
    CliResult r = run_cli("render " + (dir / "bad.json").string() + " -o " + out.string() + " --backend " + backend +
                          " " + c.flags);
    EXPECT_EQ(r.status, 2) << c.label << " (" << backend << "): " << r.err;
    EXPECT_NE(r.err.find(c.expect), std::string::npos) << "expected '" << c.expect << "' in: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line expected: " << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
    EXPECT_FALSE(std::filesystem::exists(out)) << "output written on bad input";
  }
  // No temp files left behind either.
  for (auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_EQ(e.path().filename(), "bad.json") << "left behind: " << e.path();
  std::filesystem::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Cases, CliBadInput,
    ::testing::Values(
        CliCase{"unknown_key", R"({"film": {"spp": 4, "sppp": 3}})", "", "film.sppp: unknown key"},
        CliCase{"negative_sigma",
                R"({"media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0,0,0], "radius": 1}}, "sigma_s": [0,-1,0]}]})",
                "", "media[0].sigma_s: must be >= 0"},
        CliCase{"g_out_of_range",
                R"({"media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0,0,0], "radius": 1}}, "g": 1}]})",
                "", "media[0].g"},
        CliCase{"spp_zero", R"({"film": {"spp": 0}})", "", "film.spp"},
        // Bad light parameters (docs/scene-format.md "lights").
        CliCase{"light_negative_intensity",
                R"({"lights": [{"type": "point", "position": [0,1,0], "intensity": [1,-1,1]}]})", "",
                "bad.json: lights[0].intensity: must be >= 0 in every channel"},
        CliCase{"light_zero_direction",
                R"({"lights": [{"type": "distant", "direction": [0,0,0], "irradiance": [1,1,1]}]})", "",
                "bad.json: lights[0].direction: must not be zero"},
        CliCase{"light_cone_below_falloff",
                R"({"lights": [{"type": "spot", "position": [0,1,0], "direction": [0,-1,0], "intensity": [1,1,1],
                    "cone_deg": 10, "falloff_deg": 20}]})",
                "", "bad.json: lights[0].cone_deg: must be >= falloff_deg"},
        CliCase{"light_radius_zero",
                R"({"lights": [{"type": "sphere", "center": [0,1,0], "radius": 0, "radiance": [1,1,1]}]})", "",
                "bad.json: lights[0].radius: must be > 0"},
        CliCase{"light_without_light_sampling",
                R"({"integrator": {"mis": false}, "lights": [{"type": "point", "position": [0,1,0], "intensity": [1,1,1]}]})",
                "", "bad.json: integrator.mis: false turns off light sampling"},
        // Integrator keys that contradict each other (docs/scene-format.md "integrator").
        CliCase{"mis_with_absorption", R"({"integrator": {"mis": true, "emission_estimator": "absorption"}})", "",
                "bad.json: integrator.emission_estimator: \"absorption\" contradicts \"mis\": true"},
        CliCase{"light_only_without_mis", R"({"integrator": {"light_only": true, "mis": false}})", "",
                "bad.json: integrator.light_only: true asks for light sampling, which \"mis\": false turns off"},
        CliCase{"light_only_with_absorption",
                R"({"integrator": {"light_only": true, "emission_estimator": "absorption"}})", "",
                "bad.json: integrator.light_only: true asks for light sampling, which needs the collision estimator"},
        CliCase{"wrong_type", R"({"film": {"height": [3]}})", "", "film.height: expected an integer"},
        CliCase{"default_lights_not_boolean", R"({"default_lights": "no"})", "",
                "bad.json: default_lights: expected true or false"},
        CliCase{"not_json", "this is not json", "", "invalid JSON"},
        // Checkpoints carry no AOVs (docs/compositing.md "AOVs").
        CliCase{"aovs_with_resume", kSphere, "--aovs --resume", "--resume: checkpoints do not carry AOVs (--aovs)"},
        CliCase{"film_aovs_with_checkpoint",
                R"({"film": {"width": 8, "height": 8, "spp": 1, "aovs": true},
                    "media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0,1,0], "radius": 1}}}]})",
                "--checkpoint 5", "film.aovs)"},
        CliCase{"flag_spp_zero", kSphere, "--spp 0", "--spp"},
        CliCase{"vdb_missing_file", R"({"media": [{"type": "vdb", "file": "nothere.vdb"}]})", "",
                "nothere.vdb: file not found"},
        CliCase{"vdb_missing_grid",
                R"({"media": [{"type": "vdb", "file": ")" PYROLUME_SOURCE_DIR R"(/assets/volumes/fire.vdb", "source": "houdini", "density_grid": "smoke"}]})",
                "", "density grid \"smoke\": no such grid; the file has: \"density\""},
        CliCase{"vdb_not_a_vdb", R"({"media": [{"type": "vdb", "file": ")" PYROLUME_SOURCE_DIR R"(/README.md"}]})", "",
                "not an OpenVDB (.vdb) or NanoVDB (.nvdb) file"}),
    [](const ::testing::TestParamInfo<CliCase>& info) { return std::string(info.param.label); });

TEST(Cli, MissingSceneFile) {
  CliResult r = run_cli("render /nonexistent/scene.json -o /tmp/never.exr --backend cpu");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("/nonexistent/scene.json: no such file"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists("/tmp/never.exr"));
}

TEST(Cli, UnknownBackend) {
  CliResult r = run_cli("render x.json --backend metal");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("--backend"), std::string::npos) << r.err;
}

// `render` of the sphere on the CPU with `flags` into dir/out_name: exit 2, an
// error holding `expect`, and no file written.
void expect_output_refused(const std::string& flags, const std::string& out_name, const std::string& expect) {
  auto dir = temp_dir("cli-out-" + out_name);
  write_file(dir / "s.json", kSphere);
  CliResult r =
      run_cli("render " + (dir / "s.json").string() + " --backend cpu " + flags + " -o " + (dir / out_name).string());
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find(expect), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / out_name));
  std::filesystem::remove_all(dir);
}

TEST(Cli, UnknownImageType) { expect_output_refused("", "x.tiff", "x.tiff: unknown image type"); }

// AOVs are layers of an EXR: PNG has none.
TEST(Cli, AovsNeedAnExr) { expect_output_refused("--aovs", "x.png", "x.png: --aovs needs an .exr output"); }

// Seconds must be positive and finite: --time-limit 0 used to mean "no limit",
// and nan, inf or a trailing unit slipped past CLI11's number checks. Refused
// while the command line is parsed, before a backend exists: one backend suffices.
TEST(Cli, SecondsMustBePositiveAndFinite) {
  auto dir = temp_dir("cliseconds");
  write_file(dir / "s.json", kSphere);
  const auto out = dir / "o.exr";
  const std::pair<const char*, const char*> cases[] = {
      {"--time-limit", "0"},   {"--time-limit", "-1"},  {"--time-limit", "nan"}, {"--time-limit", "inf"},
      {"--time-limit", "''"},  {"--time-limit", "5s"},  {"--checkpoint", "nan"}, {"--checkpoint", "inf"},
      {"--checkpoint", "1e999"}};
  for (auto [flag, value] : cases) {
    CliResult r = run_cli("render " + (dir / "s.json").string() + " -o " + out.string() + " --backend cpu " + flag +
                          " " + value);
    const std::string label = std::string(flag) + " " + value;
    EXPECT_EQ(r.status, 2) << label << ": " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << label << ": " << r.err;
    EXPECT_NE(r.err.find(std::string(flag) + ": must be a positive, finite number of seconds"), std::string::npos)
        << label << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << label << ": " << r.out;
    EXPECT_FALSE(std::filesystem::exists(out)) << label;
  }
  std::filesystem::remove_all(dir);
}
