// `pyrolume blackbody` (run_blackbody_command): CSV contract, inclusive range,
// hard temperatures, bad arguments, and the swatch strip PNG.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <stb_image.h>

#include "color/Blackbody.h"
#include "color/SwatchStrip.h"
#include "image/AtomicFile.h"
#include "support/TestSupport.h"

using namespace pyrolume;
using namespace pyrolume::color;

namespace {

struct CommandRun {
  int status;
  std::string out, err;
};

CommandRun run(double from, double to, double step, BlackbodyMode mode = BlackbodyMode::Seed, int observer = 2,
        const std::string& png = "") {
  std::ostringstream out, err;
  const int status = run_blackbody_command(from, to, step, mode, observer, png, out, err, write_file_atomic);
  return {status, out.str(), err.str()};
}

std::vector<std::string> lines(const std::string& s) {
  std::vector<std::string> v;
  std::istringstream ss(s);
  for (std::string l; std::getline(ss, l);) v.push_back(l);
  return v;
}

std::vector<std::string> fields(const std::string& line) {
  std::vector<std::string> v;
  std::istringstream ss(line);
  for (std::string f; std::getline(ss, f, ',');) v.push_back(f);
  return v;
}

}  // namespace

TEST(BlackbodyCommand, HeaderAndInclusiveRange) {
  CommandRun r = run(1000, 2000, 250);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(r.err.empty());
  auto l = lines(r.out);
  ASSERT_EQ(l.size(), 6u);
  EXPECT_EQ(l[0], "kelvin,x,y,r,g,b");
  EXPECT_EQ(fields(l[1])[0], "1000");
  EXPECT_EQ(fields(l[5])[0], "2000");

  r = run(2856, 2856, 1);
  ASSERT_EQ(r.status, 0);
  l = lines(r.out);
  ASSERT_EQ(l.size(), 2u) << "--from 2856 --to 2856 prints one row";
  auto f = fields(l[1]);
  ASSERT_EQ(f.size(), 6u);
  EXPECT_NEAR(std::stod(f[1]), 0.44757, 2e-4);
  EXPECT_NEAR(std::stod(f[2]), 0.40745, 2e-4);

  // Accumulated steps that land a hair above --to still include it.
  r = run(0.1, 0.7, 0.1);
  ASSERT_EQ(r.status, 0);
  EXPECT_EQ(lines(r.out).size(), 8u);
  r = run(1000, 1999, 500);
  EXPECT_EQ(lines(r.out).size(), 3u) << "1000, 1500 (2000 is beyond --to)";
}

TEST(BlackbodyCommand, AStepBelowTheSpacingOfDoublesEnds) {
  // 1e300 + 1 == 1e300: stepping by 1 never passes --to. This used to loop,
  // growing its list until std::bad_alloc; the row count bounds it.
  CommandRun r = run(1e300, 1e300, 1);
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(lines(r.out).size(), 2u) << r.out;
  EXPECT_EQ(fields(lines(r.out)[1])[0], "1e+300");
  r = run(1e300, 2e300, 1);  // 1e300 rows asked for: refused, naming the limit
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("rows requested, at most"), std::string::npos) << r.err;
}

TEST(BlackbodyCommand, RowsMatchTheLibrary) {
  CommandRun r = run(3000, 3000, 1, BlackbodyMode::Peak, 10);
  ASSERT_EQ(r.status, 0);
  auto f = fields(lines(r.out)[1]);
  const glm::dvec2 xy = blackbody_xy(3000, 10);
  const glm::dvec3 rgb = blackbody_rgb(3000, BlackbodyMode::Peak, 10);
  EXPECT_NEAR(std::stod(f[1]), xy.x, 1e-6);
  EXPECT_NEAR(std::stod(f[2]), xy.y, 1e-6);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(std::stod(f[3 + c]), rgb[c], 1e-5 * rgb[c]);
}

TEST(BlackbodyCommand, HardTemperatures) {
  for (double T : {0.0, 1e-3, 1e6}) {
    for (auto mode : {BlackbodyMode::Seed, BlackbodyMode::Peak, BlackbodyMode::Physical}) {
      CommandRun r = run(T, T, 1, mode);
      ASSERT_EQ(r.status, 0) << T << ": " << r.err;
      auto f = fields(lines(r.out).at(1));
      ASSERT_EQ(f.size(), 6u);
      for (int c = 3; c < 6; ++c) {
        const double v = std::stod(f[c]);
        EXPECT_TRUE(std::isfinite(v) && v >= 0.0) << T << " " << f[c];
      }
      if (T < 1.0) {
        EXPECT_EQ(f[1], "nan");
        EXPECT_EQ(f[2], "nan");
      }
    }
  }
}

TEST(BlackbodyCommand, BadArgumentsExit2WithOneLine) {
  const double nan = std::nan("");
  struct Case { double from, to, step; int observer; const char* key; };
  const Case cases[] = {{1000, 2000, 0, 2, "--step"},     {1000, 2000, -100, 2, "--step"}, {2000, 1000, 100, 2, "--to"},
                        {-5, 1000, 100, 2, "--from"},     {nan, 1000, 100, 2, "--from"},   {0, nan, 1, 2, "--to"},
                        {0, 1000, nan, 2, "--step"},      {0, 1e6, 1e-3, 2, "--step"},     {1000, 2000, 100, 3, "--observer"},
                        {0, INFINITY, 1, 2, "--to"}};
  for (const Case& c : cases) {
    CommandRun r = run(c.from, c.to, c.step, BlackbodyMode::Seed, c.observer);
    EXPECT_EQ(r.status, 2) << c.key;
    EXPECT_TRUE(r.out.empty()) << c.key;
    EXPECT_NE(r.err.find(c.key), std::string::npos) << r.err;
    EXPECT_EQ(lines(r.err).size(), 1u) << r.err;
  }
}

TEST(BlackbodyCommand, SwatchStripPng) {
  const auto dir = test::temp_dir("swatch");
  const auto png = dir / "strip.png";
  CommandRun r = run(1000, 10000, 1500, BlackbodyMode::Physical, 2, png.string());  // 1000, 2500, ..., 10000: 7 swatches
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(lines(r.out).size(), 8u);
  int w = 0, h = 0, comp = 0;
  unsigned char* px = stbi_load(png.string().c_str(), &w, &h, &comp, 3);
  ASSERT_NE(px, nullptr);
  const SwatchStrip expected = render_swatch_strip({1000, 2500, 4000, 5500, 7000, 8500, 10000});
  EXPECT_EQ(w, expected.width);
  EXPECT_EQ(h, expected.height);
  ASSERT_EQ(size_t(w) * h * 3, expected.rgb.size());
  EXPECT_TRUE(std::equal(expected.rgb.begin(), expected.rgb.end(), px));
  const int sw = w / 7;
  auto at = [&](int x, int y) { return px + 3 * (size_t(y) * w + x); };
  // 1000 K deep red, 10 000 K blue-white (blue the largest channel).
  const unsigned char* red = at(sw / 2, 10);
  EXPECT_EQ(red[0], 255);
  EXPECT_LT(red[1], 110);
  EXPECT_EQ(red[2], 0);
  const unsigned char* blue = at(6 * sw + sw / 2, 10);
  EXPECT_EQ(blue[2], 255);
  EXPECT_GT(blue[0], 180);
  // Labels: light text pixels in the band under the swatches.
  int text = 0;
  for (int y = 96; y < h; ++y)
    for (int x = 0; x < w; ++x) text += at(x, y)[0] > 200;
  EXPECT_GT(text, 100);
  stbi_image_free(px);
  // Only the PNG is left in the folder: no temp file.
  int files = 0;
  for (auto& e : std::filesystem::directory_iterator(dir)) files += 1, (void)e;
  EXPECT_EQ(files, 1);
  std::filesystem::remove_all(dir);
}

TEST(BlackbodyCommand, UnwritablePngExits2AndPrintsNothing) {
  const auto dir = test::temp_dir("swatch-bad");
  CommandRun r = run(1000, 2000, 500, BlackbodyMode::Seed, 2, (dir / "missing" / "strip.png").string());
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(r.out.empty());
  EXPECT_NE(r.err.find("--png"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "missing"));
  std::filesystem::remove_all(dir);
}

TEST(BlackbodyCommand, StripScalesToManySwatches) {
  std::vector<double> t;
  for (int i = 0; i < 2000; ++i) t.push_back(1000 + i * 10.0);
  const SwatchStrip s = render_swatch_strip(t);
  EXPECT_LE(s.width, 16384);
  EXPECT_EQ(s.width, 2000 * 8);
  EXPECT_THROW(render_swatch_strip({}), std::invalid_argument);
  EXPECT_THROW(render_swatch_strip(std::vector<double>(kMaxSwatches + 1, 1000.0)), std::invalid_argument);
}
