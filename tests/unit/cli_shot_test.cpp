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

// Frame 3 alone and within --frames 1-4: the same camera, film and auto
// exposure (from the shot's key frame), so the same bits; every frame whole.
TEST_F(Shot, AFrameAloneIsBitIdenticalToItInTheRangeAndNoFrameIsCutOff) {
  for (int f = 1; f <= 4; ++f) write_moving_blob(dir, f);
  write_file(dir / "s.json", R"({"media": [{"type": "vdb", "file": "blob_####.vdb", "source": "kelvin"}]})");
  const std::string scene = shot_q(dir / "s.json");
  CliResult r = render(scene, "--frames 3 -o " + shot_q(dir / "alone_####.png") + " --exposure auto");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("key frame 2"), std::string::npos) << r.err;  // the middle of frames 1..4
  r = render(scene, "--frames 1-4 -o " + shot_q(dir / "all_####.png") + " --exposure auto");
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_TRUE(fs::exists(dir / "alone_0003.png"));
  EXPECT_TRUE(read_file(dir / "alone_0003.png") == read_file(dir / "all_0003.png")) << "frame 3's PNG differs";
  EXPECT_FALSE(fs::exists(dir / "alone_0002.png"));  // the key frame is not written unless asked for

  ASSERT_EQ(render(scene, "--frames 3 -o " + shot_q(dir / "alone_####.exr")).status, 0);
  ASSERT_EQ(render(scene, "--frames 1-4:1 -o " + shot_q(dir / "all_####.exr")).status, 0);
  const Image alone = read_image(dir / "alone_0003.exr");
  EXPECT_EQ(alone.rgb, read_image(dir / "all_0003.exr").rgb);
  for (int f = 1; f <= 4; ++f) {
    const Image im = read_image(dir / ("all_000" + std::to_string(f) + ".exr"));
    const auto [border, peak] = border_and_peak(im);
    EXPECT_GT(peak, 0.0) << "frame " << f;
    EXPECT_LT(border, 1e-3 * peak) << "frame " << f << " touches the image's edge";
  }
}

// `render FILE.vdb` is the shortest scene naming it, bit for bit; a pattern
// with --frames too. A missing or unreadable file: one line, exit 2.
TEST_F(Shot, ABareVdbRendersAsTheShortestSceneNamingIt) {
  for (int f = 1; f <= 4; ++f) write_moving_blob(dir, f);
  write_file(dir / "one.json", R"({"media": [{"type": "vdb", "file": "blob_0002.vdb"}]})");
  ASSERT_EQ(render(shot_q(dir / "one.json"), "-o " + shot_q(dir / "scene.exr")).status, 0);
  CliResult r = render(shot_q(dir / "blob_0002.vdb"), "-o " + shot_q(dir / "bare.exr"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_image(dir / "bare.exr").rgb, read_image(dir / "scene.exr").rgb);

  write_file(dir / "seq.json", R"({"media": [{"type": "vdb", "file": "blob_####.vdb"}]})");
  ASSERT_EQ(render(shot_q(dir / "seq.json"), "--frames 4 -o " + shot_q(dir / "s_####.exr")).status, 0);
  r = render(shot_q(dir / "blob_####.vdb"), "--frames 4 -o " + shot_q(dir / "b_####.exr"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(read_image(dir / "b_0004.exr").rgb, read_image(dir / "s_0004.exr").rgb);

  // preview loads it the same way: past the loading, only the window (no display here) may stop it.
  r = run_cli("preview " + shot_q(dir / "blob_0002.vdb") + " --frames 1 --width 16 --height 16");
  EXPECT_TRUE(r.status == 0 || r.err.find("pyrolume render") != std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("JSON"), std::string::npos) << r.err;
  // A pattern: the window shows the shot's key frame (the middle of 1..4).
  r = run_cli("preview " + shot_q(dir / "blob_####.vdb") + " --frames 1 --width 16 --height 16");
  EXPECT_TRUE(r.status == 0 || r.err.find("pyrolume render") != std::string::npos) << r.err;
  EXPECT_NE(r.err.find("preview shows the shot's key frame 2"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("not found"), std::string::npos) << r.err;

  write_file(dir / "junk.vdb", "this is not a vdb");
  r = run_cli("preview " + shot_q(dir / "junk.vdb") + " --frames 1");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("junk.vdb: not an OpenVDB"), std::string::npos) << r.err;
  for (const std::string bad : {"nope.vdb", "junk.vdb", "none_####.vdb"}) {
    const std::string frames = bad.find('#') != std::string::npos ? " --frames 1 -o " + shot_q(dir / "x_####.exr")
                                                                   : " -o " + shot_q(dir / "x.exr");
    r = render(shot_q(dir / bad), frames);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.err;
    EXPECT_NE(r.err.find(bad), std::string::npos) << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.find("JSON"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir / "x.exr") || fs::exists(dir / "x_0001.exr"));
  }
}

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

// An omitted camera.up follows the up axis, the file's or up_axis's, seen
// along each axis; along the up axis itself it falls back to the front axis.
TEST_F(Shot, AnOmittedUpFollowsTheUpAxisSeenAlongEachAxis) {
  write_tall(dir, UpAxis::Z, {{"creator", "Blender/Smoke"}});
  write_tall(dir, UpAxis::Y, {{"creator", "Houdini/SOP_OpenVDB_Write"}});
  for (UpAxis axis : {UpAxis::Z, UpAxis::Y}) {
    const glm::dvec3 up = up_axis_vector(axis);
    for (int a = 0; a < 3; ++a)
      for (double sign : {-1.0, 1.0}) {
        glm::dvec3 d(0.0);
        d[a] = sign;
        const std::string pos = "[" + std::to_string(5 * d.x) + ", " + std::to_string(5 * d.y) + ", " +
                                std::to_string(5 * d.z) + "]";
        // The file's axis (detected), and the same written as up_axis over a kelvin file.
        for (const std::string extra : {std::string(), std::string(axis == UpAxis::Z ? R"("up_axis": "z", )" : R"("up_axis": "y", )")}) {
          const std::string file = axis == UpAxis::Z ? "tall_z.vdb" : "tall_y.vdb";
          write_file(dir / "c.json", "{" + extra + R"("camera": {"position": )" + pos +
                                         R"(, "look_at": [0, 0, 0]}, "media": [{"type": "vdb", "file": ")" + file +
                                         "\"" + (extra.empty() ? "" : R"(, "source": "kelvin")") + "}]}");
          Scene s = load_scene(dir / "c.json");
          complete_scene(s, true);
          const Scene at = scene_at_frame(s, 0);
          const bool along_up = std::abs(glm::dot(d, up)) > 0.5;
          const glm::dvec3 expect = !along_up ? up : axis == UpAxis::Z ? glm::dvec3(0, 1, 0) : glm::dvec3(0, 0, -1);
          EXPECT_EQ(at.camera.up, expect) << "axis " << int(axis) << " from " << pos << " " << extra;
        }
      }
  }
}

// Rendered: seen from the side along either horizontal axis, the tall cube
// stands upright with its hot end at the top; from above it renders too.
TEST_F(Shot, AnUprightCubeRendersUprightFromEverySide) {
  write_tall(dir, UpAxis::Z);
  write_tall(dir, UpAxis::Y);
  for (UpAxis axis : {UpAxis::Z, UpAxis::Y}) {
    const glm::dvec3 up = up_axis_vector(axis);
    const glm::dvec3 centre = 0.1 * (axis == UpAxis::Z ? glm::dvec3(1.5, 1.5, 5.5) : glm::dvec3(1.5, 5.5, 1.5));
    for (int a = 0; a < 3; ++a)
      for (double sign : {-1.0, 1.0}) {
        glm::dvec3 d(0.0);
        d[a] = sign;
        const bool along_up = std::abs(glm::dot(d, up)) > 0.5;
        if (along_up && sign < 0) continue;  // one view from above is enough
        const glm::dvec3 p = centre + 4.0 * d;
        char cam[200];
        std::snprintf(cam, sizeof cam, R"("camera": {"position": [%g, %g, %g], "look_at": [%g, %g, %g]})", p.x, p.y,
                      p.z, centre.x, centre.y, centre.z);
        const std::string name = axis == UpAxis::Z ? "tall_z.vdb" : "tall_y.vdb";
        write_file(dir / "v.json", std::string("{\"up_axis\": \"") + (axis == UpAxis::Z ? "z" : "y") + "\", " + cam +
                                       R"(, "media": [{"type": "vdb", "file": ")" + name + R"(", "source": "kelvin"}]})");
        CliResult r = run_cli("render " + shot_q(dir / "v.json") + " --backend cpu --spp 2 --width 24 --height 24 -o " +
                              shot_q(dir / "v.exr"));
        ASSERT_EQ(r.status, 0) << name << " from " << d.x << "," << d.y << "," << d.z << ": " << r.err;
        if (along_up) continue;
        const Image im = read_image(dir / "v.exr");
        const double peak = border_and_peak(im).second;
        int x0 = im.width, x1 = -1, y0 = im.height, y1 = -1;
        double sum = 0.0, sum_y = 0.0;
        for (int y = 0; y < im.height; ++y)
          for (int x = 0; x < im.width; ++x) {
            const double l = shot_lum(im, x, y);
            if (l <= 0.01 * peak) continue;
            x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
            sum += l, sum_y += l * y;
          }
        const std::string at = name + " from " + std::to_string(a) + (sign > 0 ? "+" : "-");
        ASSERT_GT(sum, 0.0) << at;
        EXPECT_GT(y1 - y0, 2 * (x1 - x0)) << at << ": not upright";
        EXPECT_LT(sum_y / sum, 0.5 * (y0 + y1)) << at << ": upside down (the hot end is the top)";
      }
  }
}

// Over a ground plane the automatic camera looks down by atan(tan(fov/2)/3):
// the horizon a third of the way up from the centre, every corner still inside.
TEST(ShotFraming, OverAGroundTheCameraLooksDownAndTheHorizonIsOffCentre) {
  const std::vector<WorldBox> boxes = {{{-1, -1, 0}, {1, 1, 3}, "a"}};
  const double fov = 40.0, aspect = 16.0 / 9.0, tan_v = std::tan(fov / 2 * std::numbers::pi / 180.0);
  const Camera cam = framing_camera(boxes, UpAxis::Z, fov, aspect, ground_tilt_deg(fov));
  const glm::dvec3 f = glm::normalize(cam.look_at - cam.position);
  const glm::dvec3 r = glm::normalize(glm::cross(f, cam.up)), u = glm::cross(r, f);
  EXPECT_LT(f.z, 0.0);  // looks down
  const glm::dvec3 horizon(0, 1, 0);  // straight ahead, level
  EXPECT_NEAR(glm::dot(horizon, u) / glm::dot(horizon, f) / tan_v, 1.0 / 3.0, 1e-12);
  double fill = 0.0;
  for (int c = 0; c < 8; ++c) {
    const glm::dvec3 q = glm::dvec3((c & 1) ? 1 : -1, (c & 2) ? 1 : -1, (c & 4) ? 3 : 0) - cam.position;
    fill = std::max({fill, std::abs(glm::dot(q, r)) / glm::dot(q, f) / (tan_v * aspect),
                     std::abs(glm::dot(q, u)) / glm::dot(q, f) / tan_v});
  }
  EXPECT_NEAR(fill, 1.0 / 1.05, 1e-9);

  // complete_scene tilts only where a plane lies across the up axis.
  const fs::path dir = temp_dir("shot-ground");
  write_tall(dir, UpAxis::Z);
  for (const bool ground : {false, true}) {
    write_file(dir / "g.json", std::string(R"({"up_axis": "z", "media": [{"type": "vdb", "file": "tall_z.vdb"}])") +
                                   (ground ? R"(, "shapes": [{"plane": {"normal": [0, 0, 1]}}]})" : "}"));
    Scene s = load_scene(dir / "g.json");
    complete_scene(s, true);
    const glm::dvec3 g = glm::normalize(s.camera.look_at - s.camera.position);
    EXPECT_NEAR(-g.z, ground ? std::sin(ground_tilt_deg(s.camera.fov_deg) * std::numbers::pi / 180.0) : 0.0, 1e-12);
  }
  fs::remove_all(dir);
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
