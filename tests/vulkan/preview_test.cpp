// `pyrolume preview` (issue 7): the window under Xvfb shows the same image as
// `render` at the same spp, the headless path fails with one line and status 2,
// and the camera moves keep their geometry.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <regex>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "image/DisplayTransform.h"
#include "image/ImageIo.h"
#include "scene/Scene.h"
#include "shared/view_transform.h"
#include "preview/DisplayPass.h"
#include "preview/OrbitCamera.h"
#include "support/TestSupport.h"

using namespace pyrolume;
using namespace pyrolume::test;
namespace fs = std::filesystem;

namespace {

const fs::path kSpheres = fs::path(PYROLUME_SOURCE_DIR) / "assets/scenes/homogeneous_spheres.json";

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (!path) return false;
  std::stringstream ss(path);
  for (std::string dir; std::getline(ss, dir, ':');)
    if (!dir.empty() && ::access((fs::path(dir) / program).c_str(), X_OK) == 0) return true;
  return false;
}

// run_cli with a prefix (xvfb-run, env): "PREFIX pyrolume ARGS".
CliResult run_wrapped(const std::string& prefix, const std::string& args) {
  auto dir = temp_dir("preview-cli");
  auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  std::string cmd = prefix + " " + pyrolume_bin() + " " + args + " >" + out.string() + " 2>" + err.string();
  int raw = std::system(cmd.c_str());
  CliResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = read_file(out);
  r.err = read_file(err);
  fs::remove_all(dir);
  return r;
}

size_t count_lines(const std::string& s) { return size_t(std::count(s.begin(), s.end(), '\n')); }

// What a view shows of exposed linear radiance, display-linear (the sRGB
// encode undone), as PNG output computes it.
glm::vec3 shown_linear(glm::vec3 exposed, ViewTransform view) {
  const glm::vec3 e = display::view_display(exposed, view_shader_id(view));
  return {srgb_decode(e.x), srgb_decode(e.y), srgb_decode(e.z)};
}

// The window shows N frames, the screenshot is what it showed, and that agrees
// with `render` at the same total spp, seen through the same view and exposure.
// The view is the scene's film.view, or with `by_flag` preview's --view.
void check_screenshot_matches_render(ViewTransform view, double exposure, bool by_flag = false) {
  if (!on_path("xvfb-run")) GTEST_SKIP() << "xvfb-run is not installed (Debian package xvfb): no display to test on";
  auto dir = temp_dir("preview");
  const fs::path shot = dir / "shot.png", ref = dir / "ref.exr", scene = dir / "spheres.json";
  const std::string size = " --width 96 --height 54";
  std::string text = read_file(kSpheres);
  if (!by_flag)
    text.replace(text.find("\"film\": {"), 9, "\"film\": {\"view\": \"" + std::string(to_string(view)) + "\", ");
  write_file(scene, text);
  std::string flags = exposure != 0.0 ? " --exposure " + std::to_string(exposure) : "";
  if (by_flag) flags += " --view " + std::string(to_string(view));

  // Validation on even when run outside ctest: the preview must raise no messages.
  CliResult p = run_wrapped("PYROLUME_VALIDATION=1 xvfb-run -a",
                            "preview " + scene.string() + " --frames 16 --screenshot " + shot.string() + size + flags);
  if (p.status == 2 && p.err.find("no GLFW") != std::string::npos)
    GTEST_SKIP() << "this build has no preview window (GLFW was not found at configure time)";
  ASSERT_EQ(p.status, 0) << p.err;
  EXPECT_EQ(p.err.find("vulkan validation:"), std::string::npos) << p.err;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(p.out, m, std::regex(R"(preview: (\d+) frames, (\d+) spp, 96x54)"))) << p.out;
  EXPECT_EQ(std::stoi(m[1]), 16);
  const int spp = std::stoi(m[2]);
  ASSERT_GE(spp, 16);  // at least one sample per frame
  ASSERT_TRUE(fs::exists(shot));

  CliResult r = run_cli("render " + scene.string() + " -o " + ref.string() + " --variance --spp " +
                        std::to_string(spp) + size);
  ASSERT_EQ(r.status, 0) << r.err;

  Image shown = read_image(shot);  // sRGB-decoded to linear
  Image want = read_image(ref);
  ASSERT_EQ(shown.width, 96);
  ASSERT_EQ(shown.height, 54);
  ASSERT_TRUE(want.has_variance());
  const double n = double(shown.pixel_count());

  // What the window should show, display-linear: the view of mean · 2^exposure
  // (standard: clamp(·, 0, 1); the others: shown_linear), per pixel.
  const float scale = float(std::exp2(exposure));
  Image shown_want = want;
  for (int y = 0; y < want.height; ++y)
    for (int x = 0; x < want.width; ++x) {
      const glm::vec3 L(want.at(x, y, 0) * scale, want.at(x, y, 1) * scale, want.at(x, y, 2) * scale);
      const glm::vec3 d = view == ViewTransform::Standard ? glm::clamp(L, 0.0f, 1.0f) : shown_linear(L, view);
      for (int c = 0; c < 3; ++c) shown_want.at(x, y, c) = d[c];
    }
  // The render's per-pixel variance of the mean, through the exposure.
  for (float& v : want.variance) v *= scale * scale;

  // Per channel, the image means must agree within 4 · 2 · SE + q (standard
  // view). SE = sqrt(Σ var_i) / n is the standard error of the render's image
  // mean (var_i: its per-pixel variance of the mean, from --variance). The
  // preview's mean has the same SE; the two share the RNG scheme, so they may
  // be correlated, and SE(A − B) ≤ SE_A + SE_B = 2·SE holds whatever the
  // correlation. Clamping is 1-Lipschitz, so it cannot raise the SE.
  // q bounds the 8-bit rounding: ≤ 0.5/255 in the encoded value, times the
  // steepest slope of the sRGB decode (2.4/1.055 at V = 1) in linear units.
  // The other views are not linear, so only the per-pixel test below applies to them.
  const double q = 0.5 / 255.0 * 2.4 / 1.055;
  double brightest = 0.0;
  for (int c = 0; c < 3; ++c) {
    double sum_shown = 0, sum_want = 0, sum_var = 0;
    for (int y = 0; y < shown.height; ++y)
      for (int x = 0; x < shown.width; ++x) {
        sum_shown += shown.at(x, y, c);
        sum_want += shown_want.at(x, y, c);
        sum_var += want.var_at(x, y, c);
      }
    const double mean_shown = sum_shown / n, mean_want = sum_want / n, se = std::sqrt(sum_var) / n;
    ASSERT_TRUE(std::isfinite(se)) << "channel " << c;
    if (view == ViewTransform::Standard)
      EXPECT_NEAR(mean_shown, mean_want, 8.0 * se + q) << "channel " << c << ", SE " << se << ", spp " << spp;
    brightest = std::max(brightest, mean_shown);
  }
  EXPECT_GT(brightest, 0.05) << "the screenshot is (nearly) black";

  // Per pixel, so a flipped or channel-swapped window cannot pass on the means:
  // each pixel within 4 · 2 · sigma + q, sigma² pooled over the 3×3
  // neighbourhood (a per-pixel variance from a few dozen samples can be far
  // too small, e.g. 0 where no sample happened to hit a rare bright path).
  // Through the other views, which mix the channels, the band is where the view takes
  // the corners of the box mean ± 8·sigma (per channel): q plus the largest
  // change of the channel over those 8 corners, plus the GLSL-vs-C++
  // difference that view_transform_gpu_test allows (1e-3 encoded).
  // Allow the 0.25 % of pixel channels a correct renderer may miss (Mitsuba's rule).
  auto pooled_var = [&](int x, int y, int c) {
    double v = 0;
    int k = 0;
    for (int yy = std::max(0, y - 1); yy <= std::min(want.height - 1, y + 1); ++yy)
      for (int xx = std::max(0, x - 1); xx <= std::min(want.width - 1, x + 1); ++xx, ++k) v += want.var_at(xx, yy, c);
    return v / k;
  };
  int outliers = 0;
  for (int y = 0; y < shown.height; ++y)
    for (int x = 0; x < shown.width; ++x) {
      glm::vec3 band;
      if (view == ViewTransform::Standard) {
        for (int c = 0; c < 3; ++c) band[c] = float(8.0 * std::sqrt(pooled_var(x, y, c)) + q);
      } else {
        const glm::vec3 L(want.at(x, y, 0) * scale, want.at(x, y, 1) * scale, want.at(x, y, 2) * scale);
        const glm::vec3 d(8.0 * std::sqrt(pooled_var(x, y, 0)), 8.0 * std::sqrt(pooled_var(x, y, 1)),
                          8.0 * std::sqrt(pooled_var(x, y, 2)));
        const glm::vec3 centre = shown_linear(L, view);
        band = glm::vec3(float(q + 1e-3 * 2.4 / 1.055));
        glm::vec3 spread(0.0f);
        for (int corner = 0; corner < 8; ++corner) {
          const glm::vec3 s(corner & 1 ? 1.0f : -1.0f, corner & 2 ? 1.0f : -1.0f, corner & 4 ? 1.0f : -1.0f);
          spread = glm::max(spread, glm::abs(shown_linear(L + s * d, view) - centre));
        }
        band += spread;
      }
      for (int c = 0; c < 3; ++c)
        if (std::abs(shown.at(x, y, c) - shown_want.at(x, y, c)) > band[c]) ++outliers;
    }
  EXPECT_LE(outliers, int(0.0025 * n * 3)) << outliers << " of " << n * 3 << " pixel channels differ";
  fs::remove_all(dir);
}

}  // namespace

// The standard view, with --exposure: the window shows clamp(mean · 2^EV, 0, 1).
TEST(Preview, ScreenshotUnderXvfbMatchesRender) { check_screenshot_matches_render(ViewTransform::Standard, -1.0); }

// AgX: the window shows AgX of the mean.
TEST(Preview, AgxScreenshotMatchesRender) { check_screenshot_matches_render(ViewTransform::AgX, 0.0); }

// Filmic, chosen by --view (whose output is sRGB-encoded already, unlike the
// other views': the shader must not encode it twice).
TEST(Preview, FilmicByFlagScreenshotMatchesRender) { check_screenshot_matches_render(ViewTransform::Filmic, 0.5, true); }

TEST(Preview, NoDisplayIsOneLineAndStatus2) {
  // Without a display the window cannot open: one line that points at `render`
  // (a build without GLFW says the same, for its own reason).
  CliResult r = run_wrapped("env -u DISPLAY -u WAYLAND_DISPLAY", "preview " + kSpheres.string() + " --frames 1");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("pyrolume render"), std::string::npos) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
}

TEST(Preview, ScreenshotNeedsFrames) {
  auto dir = temp_dir("preview-args");
  CliResult r = run_cli("preview " + kSpheres.string() + " --screenshot " + (dir / "a.png").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("--frames"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "a.png"));
  fs::remove_all(dir);
}

TEST(Preview, BadSceneIsInputError) {
  CliResult r = run_wrapped("env -u DISPLAY", "preview /nonexistent/scene.json --frames 1");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(count_lines(r.err), 1u) << r.err;
  EXPECT_NE(r.err.find("/nonexistent/scene.json"), std::string::npos) << r.err;
}

// --- camera moves (no window needed) ---

TEST(PreviewCamera, OrbitKeepsDistanceAndLookAt) {
  Camera cam;
  cam.position = {0, 1, -6};
  cam.look_at = {0, 1, 0};
  const double d0 = glm::length(cam.position - cam.look_at);
  preview::orbit(cam, 0.7, 0.3);
  EXPECT_NEAR(glm::length(cam.position - cam.look_at), d0, 1e-9);
  EXPECT_EQ(cam.look_at, glm::dvec3(0, 1, 0));
  // A pure yaw keeps the height above look_at.
  Camera yaw = cam;
  preview::orbit(yaw, 1.1, 0.0);
  EXPECT_NEAR(yaw.position.y, cam.position.y, 1e-9);
  // Full turn: back where it started.
  Camera turn = cam;
  preview::orbit(turn, 2.0 * M_PI, 0.0);
  EXPECT_NEAR(glm::length(turn.position - cam.position), 0.0, 1e-9);
}

TEST(PreviewCamera, PitchStopsShortOfThePole) {
  Camera cam;
  cam.position = {0, 1, -6};
  cam.look_at = {0, 1, 0};
  preview::orbit(cam, 0.0, -10.0);  // far past straight above
  glm::dvec3 dir = glm::normalize(cam.position - cam.look_at);
  EXPECT_LT(dir.y, 1.0);
  EXPECT_NEAR(std::acos(dir.y), 0.02, 1e-9);
  preview::orbit(cam, 0.0, 10.0);  // far past straight below
  dir = glm::normalize(cam.position - cam.look_at);
  EXPECT_NEAR(std::acos(dir.y), M_PI - 0.02, 1e-9);
}

TEST(PreviewCamera, PanMovesBothAndZoomScalesDistance) {
  Camera cam;
  cam.position = {0, 1, -6};
  cam.look_at = {0, 1, 0};
  cam.fov_deg = 40;
  const glm::dvec3 offset = cam.position - cam.look_at;
  preview::pan(cam, 100, 0, 200);  // drag right by half the viewport height
  EXPECT_NEAR(glm::length(cam.position - cam.look_at - offset), 0.0, 1e-12);
  // Dragging right moves the camera left (-image x); image x = cross(forward, up) = -X here.
  const double half_height = 6.0 * std::tan(glm::radians(20.0));
  EXPECT_NEAR(cam.look_at.x, half_height, 1e-9);
  preview::zoom(cam, 1.0);
  EXPECT_NEAR(glm::length(cam.position - cam.look_at), 6.0 * 0.9, 1e-9);
  preview::zoom(cam, -2.0);
  EXPECT_NEAR(glm::length(cam.position - cam.look_at), 6.0 / 0.9, 1e-9);
}

TEST(PreviewDisplay, FitImageLetterboxes) {
  auto r = preview::fit_image(96, 54, 96, 54);  // the usual case: 1:1
  EXPECT_EQ(r.x, 0u);
  EXPECT_EQ(r.y, 0u);
  EXPECT_EQ(r.width, 96u);
  EXPECT_EQ(r.height, 54u);
  r = preview::fit_image(96, 54, 200, 54);  // wider window: bars left and right
  EXPECT_EQ(r.width, 96u);
  EXPECT_EQ(r.height, 54u);
  EXPECT_EQ(r.x, 52u);
  r = preview::fit_image(100, 50, 300, 300);  // taller window: bars above and below
  EXPECT_EQ(r.width, 300u);
  EXPECT_EQ(r.height, 150u);
  EXPECT_EQ(r.y, 75u);
}
