// Issue 46: a shot framed once (docs/render-farm.md "One shot, one framing"),
// a bare VDB as a scene, the camera's up and tilt, the --exposure range,
// "did you mean", and info's small sizes. CPU backend, tiny images.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "image/ImageIo.h"
#include "render/SceneSetup.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"
#include "util/Suggest.h"
#include "volume/VdbInfo.h"

using namespace pyrolume;
using namespace pyrolume::test;
namespace fs = std::filesystem;

namespace cli_shot_test {

std::string shot_q(const fs::path& p) { return "'" + p.string() + "'"; }

double shot_lum(const Image& im, int x, int y) {
  const float* p = &im.rgb[3 * (size_t(y) * size_t(im.width) + size_t(x))];
  return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
}

// A 6³-voxel hot cube (kelvin temperatures) that moves 10 voxels along +X
// per frame and burns hotter each frame: frames 1..4 of blob_####.vdb.
void write_moving_blob(const fs::path& dir, int frame) {
  char name[32];
  std::snprintf(name, sizeof name, "blob_%04d.vdb", frame);
  const VoxelBox box{{10 * (frame - 1), 0, 0}, {10 * (frame - 1) + 5, 5, 5}};
  const float kelvin = 1200.0f + 250.0f * float(frame);
  write_vdb(dir / name, {make_float_grid("density", Lattice{}, box, [](int, int, int) { return 4.0f; }),
                         make_float_grid("temperature", Lattice{}, box, [=](int, int, int) { return kelvin; })});
}

// The largest luminance on the image's border, and anywhere.
std::pair<double, double> border_and_peak(const Image& im) {
  double border = 0.0, peak = 0.0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const double l = shot_lum(im, x, y);
      peak = std::max(peak, l);
      if (x == 0 || y == 0 || x == im.width - 1 || y == im.height - 1) border = std::max(border, l);
    }
  return {border, peak};
}

class Shot : public ::testing::Test {
 protected:
  fs::path dir = temp_dir("cli-shot");
  void TearDown() override { fs::remove_all(dir); }
  CliResult render(const std::string& scene, const std::string& flags) {
    return run_cli("render " + scene + " --backend cpu --spp 4 --width 48 --height 24 " + flags);
  }
};

}  // namespace cli_shot_test

using namespace cli_shot_test;

// A tall cube whose temperature rises with height, up `axis`.
fs::path write_tall(const fs::path& dir, UpAxis axis, const FileMetadata& meta = {}) {
  const bool z = axis == UpAxis::Z;
  const VoxelBox box{{0, 0, 0}, z ? glm::ivec3(3, 3, 11) : glm::ivec3(3, 11, 3)};
  const fs::path f = dir / (z ? "tall_z.vdb" : "tall_y.vdb");
  write_vdb(f, {make_float_grid("density", Lattice{}, box, [](int, int, int) { return 3.0f; }),
                make_float_grid("temperature", Lattice{}, box,
                                [=](int, int j, int k) { return 1000.0f + 90.0f * float(z ? k : j); })},
            meta);
  return f;
}

// --exposure: a finite number within ±30 stops or auto; anything else one
// line and exit 2 (and film.exposure the same), nothing written.
TEST_F(Shot, ExposureOutsideItsRangeIsRefused) {
  write_file(dir / "s.json", R"({"film": {"width": 4, "height": 4, "spp": 1},
    "media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0, 1, 0], "radius": 1}}}]})");
  for (const std::string bad : {"''", "1e9", "-31", "nan", "inf", "2x"}) {
    CliResult r = run_cli("render " + shot_q(dir / "s.json") + " --backend cpu -o " + shot_q(dir / "o.png") + " --exposure " + bad);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("--exposure"), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_FALSE(fs::exists(dir / "o.png"));
  }
  for (const std::string good : {"-30", "30", "auto", "1.5"}) {
    CliResult r = run_cli("render " + shot_q(dir / "s.json") + " --backend cpu -o " + shot_q(dir / "o.png") + " --exposure " + good);
    EXPECT_EQ(r.status, 0) << good << ": " << r.err;
  }
  write_file(dir / "e.json", R"({"film": {"exposure": 40}})");
  CliResult r = run_cli("render " + shot_q(dir / "e.json") + " --backend cpu -o " + shot_q(dir / "x.png"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("film.exposure: must be within"), std::string::npos) << r.err;
}

// A misspelt scene key, flag or subcommand: "did you mean" the closest known one.
TEST_F(Shot, MisspeltKeysAndFlagsGetDidYouMean) {
  write_file(dir / "s.json", R"({"film": {"width": 4, "height": 4, "spp": 1},
    "media": [{"type": "homogeneous", "bounds": {"sphere": {"center": [0, 1, 0], "radius": 1}}, "sigma_z": [1, 1, 1]}]})");
  CliResult r = run_cli("render " + shot_q(dir / "s.json") + " --backend cpu -o " + shot_q(dir / "o.exr"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("media[0].sigma_z: unknown key (did you mean \"sigma_"), std::string::npos) << r.err;
  write_file(dir / "t.json", R"({"flim": {}})");
  r = run_cli("render " + shot_q(dir / "t.json") + " --backend cpu -o " + shot_q(dir / "o.exr"));
  EXPECT_NE(r.err.find("flim: unknown key (did you mean \"film\"?)"), std::string::npos) << r.err;
  r = run_cli("render " + shot_q(dir / "t.json") + " --exposre 1 -o " + shot_q(dir / "o.exr"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("did you mean \"--exposure\"?"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  r = run_cli("rendr " + shot_q(dir / "t.json"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("did you mean \"render\"?"), std::string::npos) << r.err;
  r = run_cli("render " + shot_q(dir / "t.json") + " --zzzzzzzz 1");  // nothing near: no suggestion
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err.find("did you mean"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "o.exr"));
}

TEST(Suggest, EditDistanceAndTheClosestName) {
  EXPECT_EQ(edit_distance("", ""), 0u);
  EXPECT_EQ(edit_distance("film", "flim"), 1u);  // a swap
  EXPECT_EQ(edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(edit_distance("abc", ""), 3u);
  const std::vector<std::string> known{"density_scale", "density_grid", "temperature", "sigma_s"};
  EXPECT_EQ(closest_name("densty_scale", known), "density_scale");
  EXPECT_EQ(closest_name("Temperatur", known), "temperature");
  EXPECT_EQ(closest_name("colour", known), "");
  EXPECT_EQ(did_you_mean("sigma_z", known), " (did you mean \"sigma_s\"?)");
  EXPECT_EQ(did_you_mean("xyz", known), "");
}

// info prints a few-KiB grid's dense size in KiB, not "0.0 MiB".
TEST_F(Shot, InfoPrintsSmallSizesInKiB) {
  EXPECT_EQ(footprint_text(512.0), "512 B");
  EXPECT_EQ(footprint_text(3.0 * 1024), "3.0 KiB");
  EXPECT_EQ(footprint_text(5.5 * 1048576), "5.5 MiB");
  EXPECT_EQ(footprint_text(2.0 * 1073741824.0), "2.0 GiB");
  write_tall(dir, UpAxis::Z);
  CliResult r = run_cli("info " + shot_q(dir / "tall_z.vdb"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out.find("0.0 MiB"), std::string::npos) << r.out;
  // 4×4×12 active voxels plus one texel of padding on every side, 2 B each.
  EXPECT_NE(r.out.find("dense " + footprint_text(2.0 * 6 * 6 * 14) + " "), std::string::npos) << r.out;
}
