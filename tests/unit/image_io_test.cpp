// Image files: sRGB curve, PNG bytes, EXR round trips and channel names, atomic
// writes, and error messages that name the file.
#include <ImfChannelList.h>
#include <ImfCompression.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <gtest/gtest.h>
#include <half.h>
#include <stb_image.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <vector>

#include "image/AtomicFile.h"
#include "image/ImageIo.h"
#include "support/TestSupport.h"
#include "util/Error.h"

using namespace pyrolume;
namespace fs = std::filesystem;

namespace {

std::vector<fs::path> listing(const fs::path& dir) {
  std::vector<fs::path> v;
  for (auto& e : fs::directory_iterator(dir)) v.push_back(e.path().filename());
  return v;
}

// Expects `f` to throw InputError whose one-line message contains every needle.
template <class F>
std::string expect_input_error(F&& f, std::initializer_list<std::string> needles) {
  try {
    f();
  } catch (const InputError& e) {
    std::string msg = e.what();
    for (const auto& n : needles) EXPECT_NE(msg.find(n), std::string::npos) << "'" << n << "' not in: " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    return msg;
  }
  ADD_FAILURE() << "no InputError thrown";
  return {};
}

Image sample_image(bool with_variance) {
  Image img = make_image(3, 2, with_variance);
  const float values[] = {0.0f, 1.0f, -0.5f, 1e-8f, 123456.0f, 0.25f, 0.1f, 0.2f, 0.3f,
                          7.5f, 1e30f, 3.0f,  0.5f,  0.75f,     2.0f,  9.0f, 8.0f, 7.0f};
  img.rgb.assign(std::begin(values), std::end(values));
  if (with_variance)
    for (size_t i = 0; i < img.variance.size(); ++i) img.variance[i] = 0.001f * float(i + 1);
  return img;
}

}  // namespace

TEST(Srgb, EncodeMatchesIec61966) {
  // 255·(1.055·0.5^(1/2.4) − 0.055) = 187.516 → 188
  EXPECT_EQ(srgb_encode_u8(0.5f, 0.0), 188);
  EXPECT_EQ(srgb_encode_u8(0.25f, 0.0), 137);   // 136.960
  EXPECT_EQ(srgb_encode_u8(0.25f, 1.0), 188);   // exposure +1 doubles
  EXPECT_EQ(srgb_encode_u8(0.5f, -1.0), 137);
  EXPECT_EQ(srgb_encode_u8(0.18f, 0.0), 118);   // 117.646
  EXPECT_EQ(srgb_encode_u8(0.002f, 0.0), 7);    // linear segment: 255·12.92·0.002 = 6.589
  EXPECT_EQ(srgb_encode_u8(1.0f, 0.0), 255);
  EXPECT_EQ(srgb_encode_u8(5.0f, 0.0), 255);    // clamped
  EXPECT_EQ(srgb_encode_u8(-1.0f, 0.0), 0);
  EXPECT_EQ(srgb_encode_u8(std::numeric_limits<float>::quiet_NaN(), 0.0), 0);
  EXPECT_EQ(srgb_encode_u8(std::numeric_limits<float>::infinity(), 0.0), 255);
  EXPECT_NEAR(srgb_encode(0.0031308f), 0.040449936f, 1e-7f);  // both pieces meet here
}

TEST(Srgb, DecodeInvertsEncode) {
  EXPECT_NEAR(srgb_decode(188.0f / 255.0f), 0.50288646f, 1e-6f);
  EXPECT_NEAR(srgb_decode(7.0f / 255.0f), 0.0021246889f, 1e-8f);
  EXPECT_NEAR(srgb_decode(128.0f / 255.0f), 0.21586050f, 1e-6f);
  for (float x : {0.0f, 1e-4f, 0.003f, 0.01f, 0.2f, 0.5f, 0.9f, 1.0f})
    EXPECT_NEAR(srgb_decode(srgb_encode(x)), x, 2e-6f * std::max(1.0f, x)) << x;
}

TEST(ImageIo, PngHasSrgbBytesRowZeroOnTop) {
  auto dir = test::temp_dir("png");
  Image img = make_image(2, 2);
  const float v[] = {0.5f, 0.25f, 0.0f, 1.0f, 0.002f, 2.0f,   // top row
                     0.18f, 0.0f, 0.0f, 0.0f, 0.0f, 1.0f};    // bottom row
  img.rgb.assign(std::begin(v), std::end(v));
  write_image(dir / "a.png", img, 0.0);

  int w = 0, h = 0, n = 0;
  unsigned char* px = stbi_load((dir / "a.png").c_str(), &w, &h, &n, 0);
  ASSERT_NE(px, nullptr);
  ASSERT_EQ(w, 2);
  ASSERT_EQ(h, 2);
  ASSERT_EQ(n, 3);
  const unsigned char expected[] = {188, 137, 0, 255, 7, 255, 118, 0, 0, 0, 0, 255};
  for (int i = 0; i < 12; ++i) EXPECT_EQ(px[i], expected[i]) << "byte " << i;
  stbi_image_free(px);

  // read_image decodes sRGB back to linear.
  Image back = read_image(dir / "a.png");
  ASSERT_EQ(back.width, 2);
  ASSERT_EQ(back.height, 2);
  EXPECT_FALSE(back.has_variance());
  EXPECT_NEAR(back.at(0, 0, 0), 0.50288646f, 1e-6f);
  EXPECT_FLOAT_EQ(back.at(1, 0, 0), 1.0f);
  EXPECT_FLOAT_EQ(back.at(0, 1, 1), 0.0f);
  fs::remove_all(dir);
}

TEST(ImageIo, PngExposurePlusOneDoubles) {
  auto dir = test::temp_dir("pngexp");
  Image img = make_image(1, 1);
  img.rgb = {0.25f, 0.125f, 0.5f};
  write_image(dir / "e.PNG", img, 1.0);  // extension is case-insensitive
  int w, h, n;
  unsigned char* px = stbi_load((dir / "e.PNG").c_str(), &w, &h, &n, 3);
  ASSERT_NE(px, nullptr);
  EXPECT_EQ(px[0], 188);  // 0.5
  EXPECT_EQ(px[1], 137);  // 0.25
  EXPECT_EQ(px[2], 255);  // 1.0
  stbi_image_free(px);
  fs::remove_all(dir);
}

TEST(ImageIo, ExrRoundTripWithoutVariance) {
  auto dir = test::temp_dir("exr");
  Image img = sample_image(false);
  write_image(dir / "a.exr", img, 3.0);  // exposure must not touch EXR
  Image back = read_image(dir / "a.exr");
  EXPECT_EQ(back.width, 3);
  EXPECT_EQ(back.height, 2);
  EXPECT_EQ(back.rgb, img.rgb);
  EXPECT_FALSE(back.has_variance());

  Imf::InputFile f((dir / "a.exr").c_str());
  const Imf::ChannelList& ch = f.header().channels();
  for (const char* n : {"R", "G", "B"}) {
    ASSERT_NE(ch.findChannel(n), nullptr) << n;
    EXPECT_EQ(ch.findChannel(n)->type, Imf::FLOAT) << n;
  }
  EXPECT_EQ(ch.findChannel("variance.R"), nullptr);
  int count = 0;
  for (auto it = ch.begin(); it != ch.end(); ++it) ++count;
  EXPECT_EQ(count, 3);
  EXPECT_EQ(f.header().compression(), Imf::ZIP_COMPRESSION);
  EXPECT_EQ(listing(dir), std::vector<fs::path>{"a.exr"});  // no temp file left
  fs::remove_all(dir);
}

// Alpha (docs/compositing.md): EXR channel A, read back as written.
TEST(ImageIo, ExrRoundTripWithAlpha) {
  auto dir = test::temp_dir("exralpha");
  Image img = sample_image(true);
  img.alpha = {0.0f, 0.25f, 1.0f, 0.5f, -0.01f, 1.0f};
  write_image(dir / "a.exr", img);
  Image back = read_image(dir / "a.exr");
  EXPECT_EQ(back.rgb, img.rgb);
  EXPECT_EQ(back.variance, img.variance);
  EXPECT_EQ(back.alpha, img.alpha);
  Imf::InputFile f((dir / "a.exr").c_str());
  ASSERT_NE(f.header().channels().findChannel("A"), nullptr);
  EXPECT_EQ(f.header().channels().findChannel("A")->type, Imf::FLOAT);
  // Without alpha there is no A channel.
  write_image(dir / "b.exr", sample_image(false));
  EXPECT_FALSE(read_image(dir / "b.exr").has_alpha());
  fs::remove_all(dir);
}

// AOVs (docs/compositing.md "AOVs"): every layer's channels in the same
// single-part EXR as FLOAT, read back bit for bit; a file with some but not
// all of them is refused with one line naming the file and a missing channel.
TEST(ImageIo, ExrRoundTripWithAovs) {
  auto dir = test::temp_dir("exraovs");
  Image img = sample_image(true);
  img.alpha = {0.0f, 0.25f, 1.0f, 0.5f, 0.75f, 1.0f};
  float v = 0.5f;
  for (auto* layer : {&img.aovs.emission, &img.aovs.scatter, &img.aovs.surface, &img.aovs.background,
                      &img.aovs.albedo, &img.aovs.normal})
    for (int i = 0; i < 18; ++i) layer->push_back(v += 0.37f);
  img.aovs.depth = {0.0f, 1.5f, 1e6f, 3.25f, 0.0f, 7.0f};
  ASSERT_TRUE(img.has_aovs());
  write_image(dir / "aovs.exr", img);
  Image back = read_image(dir / "aovs.exr");
  EXPECT_EQ(back.rgb, img.rgb);
  EXPECT_EQ(back.variance, img.variance);
  EXPECT_EQ(back.alpha, img.alpha);
  EXPECT_EQ(back.aovs.emission, img.aovs.emission);
  EXPECT_EQ(back.aovs.scatter, img.aovs.scatter);
  EXPECT_EQ(back.aovs.surface, img.aovs.surface);
  EXPECT_EQ(back.aovs.background, img.aovs.background);
  EXPECT_EQ(back.aovs.albedo, img.aovs.albedo);
  EXPECT_EQ(back.aovs.normal, img.aovs.normal);
  EXPECT_EQ(back.aovs.depth, img.aovs.depth);
  {
    Imf::InputFile f((dir / "aovs.exr").c_str());
    EXPECT_FALSE(f.header().hasTileDescription());
    for (const char* n : {"emission.R", "emission.G", "emission.B", "scatter.R", "scatter.G", "scatter.B", "surface.R",
                          "surface.G", "surface.B", "background.R", "background.G", "background.B", "albedo.R",
                          "albedo.G", "albedo.B", "normal.X", "normal.Y", "normal.Z", "depth.Z"}) {
      ASSERT_NE(f.header().channels().findChannel(n), nullptr) << n;
      EXPECT_EQ(f.header().channels().findChannel(n)->type, Imf::FLOAT) << n;
    }
  }
  // Without AOVs: none of their channels, and none read back.
  write_image(dir / "plain.exr", sample_image(false));
  EXPECT_FALSE(read_image(dir / "plain.exr").has_aovs());
  EXPECT_TRUE(read_image(dir / "plain.exr").aovs.depth.empty());

  // Some AOV channels but not all: one line naming the file and a missing channel.
  {
    Imf::Header h(1, 1);
    for (const char* n : {"R", "G", "B", "albedo.R", "albedo.G", "albedo.B"}) h.channels().insert(n, Imf::Channel(Imf::FLOAT));
    float px[6] = {1, 2, 3, 0.5f, 0.5f, 0.5f};
    Imf::FrameBuffer fb;
    const char* names[6] = {"R", "G", "B", "albedo.R", "albedo.G", "albedo.B"};
    for (int c = 0; c < 6; ++c) fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(px + c), sizeof(float), sizeof(float)));
    Imf::OutputFile out((dir / "partial.exr").c_str(), h);
    out.setFrameBuffer(fb);
    out.writePixels(1);
  }
  const std::string msg = expect_input_error([&] { read_image(dir / "partial.exr"); }, {"partial.exr", "depth.Z"});
  EXPECT_EQ(msg.find('\n'), std::string::npos);
  fs::remove_all(dir);
}

// The denoiser's guide (guide.R/G/B/A) rides with the AOVs: read back bit for
// bit; a file with some guide channels but not all, or a guide without the
// AOVs, is refused with one line naming the file and the channels.
TEST(ImageIo, ExrRoundTripWithTheGuide) {
  auto dir = test::temp_dir("exrguide");
  Image img = sample_image(true);
  float v = 0.25f;
  for (auto* layer : {&img.aovs.emission, &img.aovs.scatter, &img.aovs.surface, &img.aovs.background,
                      &img.aovs.albedo, &img.aovs.normal, &img.aovs.guide})
    for (int i = 0; i < 18; ++i) layer->push_back(v += 0.29f);
  img.aovs.depth = {0.0f, 1.5f, 1e6f, 3.25f, 0.0f, 7.0f};
  img.aovs.guide_alpha = {0.0f, 0.125f, 1.0f, 0.5f, 0.75f, 1.0f};
  ASSERT_TRUE(img.aovs.has_guide());
  write_image(dir / "guide.exr", img);
  const Image back = read_image(dir / "guide.exr");
  EXPECT_EQ(back.aovs.guide, img.aovs.guide);
  EXPECT_EQ(back.aovs.guide_alpha, img.aovs.guide_alpha);
  EXPECT_EQ(back.aovs.emission, img.aovs.emission);
  {
    Imf::InputFile f((dir / "guide.exr").c_str());
    for (const char* n : {"guide.R", "guide.G", "guide.B", "guide.A"})
      ASSERT_NE(f.header().channels().findChannel(n), nullptr) << n;
  }
  // A file with the given FLOAT channels, every value 1.
  auto write_channels = [&](const fs::path& path, const std::vector<std::string>& names) {
    Imf::Header h(1, 1);
    for (const std::string& n : names) h.channels().insert(n, Imf::Channel(Imf::FLOAT));
    std::vector<float> px(names.size(), 1.0f);
    Imf::FrameBuffer fb;
    for (size_t c = 0; c < names.size(); ++c)
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(px.data() + c), sizeof(float), sizeof(float)));
    Imf::OutputFile out(path.c_str(), h);
    out.setFrameBuffer(fb);
    out.writePixels(1);
  };
  write_channels(dir / "noaovs.exr", {"R", "G", "B", "guide.R", "guide.G", "guide.B", "guide.A"});
  std::string msg = expect_input_error([&] { read_image(dir / "noaovs.exr"); }, {"noaovs.exr", "guide", "emission"});
  EXPECT_EQ(msg.find('\n'), std::string::npos);
  std::vector<std::string> names = {"R", "G", "B", "emission.R", "emission.G", "emission.B", "scatter.R", "scatter.G",
                                    "scatter.B", "surface.R", "surface.G", "surface.B", "background.R", "background.G",
                                    "background.B", "albedo.R", "albedo.G", "albedo.B", "normal.X", "normal.Y",
                                    "normal.Z", "depth.Z", "guide.R", "guide.G", "guide.B"};
  write_channels(dir / "partial.exr", names);
  msg = expect_input_error([&] { read_image(dir / "partial.exr"); }, {"partial.exr", "guide.A"});
  EXPECT_EQ(msg.find('\n'), std::string::npos);
  names.push_back("guide.A");
  write_channels(dir / "whole.exr", names);
  EXPECT_TRUE(read_image(dir / "whole.exr").aovs.has_guide());
  fs::remove_all(dir);
}

// PNG: RGB unless the image is transparent; then RGBA with straight alpha,
// the colour being RGB/A through the view transform.
TEST(ImageIo, PngHasStraightAlphaOnlyWhenTransparent) {
  auto dir = test::temp_dir("pngalpha");
  Image img = make_image(2, 1);
  img.rgb = {0.25f, 0.125f, 0.0f, 0.0f, 0.0f, 0.0f};  // premultiplied by A = 0.5, then A = 0
  img.alpha = {0.5f, 0.0f};
  write_image(dir / "opaque.png", img, 0.0);
  int w = 0, h = 0, n = 0;
  unsigned char* px = stbi_load((dir / "opaque.png").c_str(), &w, &h, &n, 0);
  ASSERT_NE(px, nullptr);
  EXPECT_EQ(n, 3);
  EXPECT_EQ(px[0], 137);  // 0.25 as it is
  stbi_image_free(px);
  img.transparent = true;
  write_image(dir / "t.png", img, 0.0);
  px = stbi_load((dir / "t.png").c_str(), &w, &h, &n, 0);
  ASSERT_NE(px, nullptr);
  ASSERT_EQ(n, 4);
  EXPECT_EQ(px[0], 188);  // 0.25 / 0.5 = 0.5
  EXPECT_EQ(px[1], 137);  // 0.125 / 0.5 = 0.25
  EXPECT_EQ(px[3], 128);  // A = 0.5
  EXPECT_EQ(px[7], 0);    // A = 0
  stbi_image_free(px);
  fs::remove_all(dir);
}

TEST(ImageIo, ExrRoundTripWithVariance) {
  auto dir = test::temp_dir("exrvar");
  Image img = sample_image(true);
  write_image(dir / "v.exr", img, 0.0);
  Image back = read_image(dir / "v.exr");
  EXPECT_EQ(back.rgb, img.rgb);
  ASSERT_TRUE(back.has_variance());
  EXPECT_EQ(back.variance, img.variance);

  Imf::InputFile f((dir / "v.exr").c_str());
  const Imf::ChannelList& ch = f.header().channels();
  for (const char* n : {"R", "G", "B", "variance.R", "variance.G", "variance.B"})
    EXPECT_NE(ch.findChannel(n), nullptr) << n;
  // Read variance.G directly: pixel (1,0) is interleaved index 4 → 0.001·5.
  std::vector<float> vg(6);
  Imf::FrameBuffer fb;
  fb.insert("variance.G", Imf::Slice(Imf::FLOAT, (char*)vg.data(), sizeof(float), 3 * sizeof(float)));
  f.setFrameBuffer(fb);
  f.readPixels(0, 1);
  EXPECT_FLOAT_EQ(vg[1], 0.005f);
  fs::remove_all(dir);
}

TEST(ImageIo, ReadsHalfRgbaAndYOnlyAndOffsetDataWindow) {
  auto dir = test::temp_dir("exrin");
  // RGBA half, 2×1, data window starting at (5, 7).
  {
    Imath::Box2i win(Imath::V2i(5, 7), Imath::V2i(6, 7));
    Imf::Header h(win, win);
    for (const char* n : {"R", "G", "B", "A"}) h.channels().insert(n, Imf::Channel(Imf::HALF));
    std::vector<Imath::half> px;
    for (float v : {0.5f, 0.25f, 2.0f, 1.0f, 4.0f, 0.0f, 0.125f, 0.5f}) px.push_back(Imath::half(v));
    Imf::FrameBuffer fb;
    const char* names[4] = {"R", "G", "B", "A"};
    const size_t hs = sizeof(Imath::half);
    char* base = (char*)px.data() - 5 * 4 * hs - 7 * 2 * 4 * hs;  // absolute data-window addressing
    for (int c = 0; c < 4; ++c) fb.insert(names[c], Imf::Slice(Imf::HALF, base + c * hs, 4 * hs, 8 * hs));
    Imf::OutputFile out((dir / "rgba.exr").c_str(), h);
    out.setFrameBuffer(fb);
    out.writePixels(1);
  }
  Image rgba = read_image(dir / "rgba.exr");
  ASSERT_EQ(rgba.width, 2);
  ASSERT_EQ(rgba.height, 1);
  EXPECT_EQ(rgba.rgb, (std::vector<float>{0.5f, 0.25f, 2.0f, 4.0f, 0.0f, 0.125f}));

  // Y-only half: gray replicated to R, G, B.
  {
    Imf::Header h(2, 1);
    h.channels().insert("Y", Imf::Channel(Imf::HALF));
    std::vector<Imath::half> y = {Imath::half(0.75f), Imath::half(3.0f)};
    Imf::FrameBuffer fb;
    fb.insert("Y", Imf::Slice(Imf::HALF, (char*)y.data(), sizeof(Imath::half), 2 * sizeof(Imath::half)));
    Imf::OutputFile out((dir / "y.exr").c_str(), h);
    out.setFrameBuffer(fb);
    out.writePixels(1);
  }
  Image gray = read_image(dir / "y.exr");
  EXPECT_EQ(gray.rgb, (std::vector<float>{0.75f, 0.75f, 0.75f, 3.0f, 3.0f, 3.0f}));
  fs::remove_all(dir);
}

TEST(ImageIo, UnknownExtensionIsInputError) {
  auto dir = test::temp_dir("ext");
  expect_input_error([&] { write_image(dir / "out.tif", sample_image(false), 0.0); }, {"out.tif", ".tif"});
  expect_input_error([&] { write_image(dir / "noext", sample_image(false), 0.0); }, {"noext"});
  EXPECT_TRUE(listing(dir).empty());
  fs::remove_all(dir);
}

TEST(ImageIo, MissingFolderThrowsAndLeavesNothing) {
  auto dir = test::temp_dir("nodir");
  auto target = dir / "missing" / "out.exr";
  expect_input_error([&] { write_image(target, sample_image(false), 0.0); }, {"out.exr", "does not exist"});
  EXPECT_FALSE(fs::exists(dir / "missing"));
  EXPECT_TRUE(listing(dir).empty());
  fs::remove_all(dir);
}

TEST(ImageIo, FailureMidWayLeavesNothingAndKeepsOldFile) {
  auto dir = test::temp_dir("midway");
  auto throwing = [](std::ostream& os) {
    os << std::string(4096, 'x');
    throw std::runtime_error("boom");
  };
  EXPECT_THROW(write_file_atomic(dir / "out.exr", throwing), std::runtime_error);
  EXPECT_TRUE(listing(dir).empty());

  // An existing file survives a failed rewrite untouched.
  test::write_file(dir / "out.exr", "old");
  EXPECT_THROW(write_file_atomic(dir / "out.exr", throwing), std::runtime_error);
  EXPECT_EQ(test::read_file(dir / "out.exr"), "old");
  EXPECT_EQ(listing(dir), std::vector<fs::path>{"out.exr"});
  fs::remove_all(dir);
}

TEST(ImageIo, RenameFailureLeavesNoTempFile) {
  auto dir = test::temp_dir("rename");
  fs::create_directory(dir / "taken.exr");  // a folder where the file should go
  expect_input_error([&] { write_image(dir / "taken.exr", sample_image(false), 0.0); }, {"taken.exr"});
  EXPECT_EQ(listing(dir), std::vector<fs::path>{"taken.exr"});
  EXPECT_TRUE(fs::is_directory(dir / "taken.exr"));
  fs::remove_all(dir);
}

TEST(ImageIo, OverwriteReplacesWholeFile) {
  auto dir = test::temp_dir("overwrite");
  test::write_file(dir / "a.exr", std::string(1 << 20, 'z'));  // longer than the new file
  write_image(dir / "a.exr", sample_image(true), 0.0);
  EXPECT_EQ(read_image(dir / "a.exr").variance, sample_image(true).variance);
  write_text_atomic(dir / "s.json", "{\"a\": 1}\n");
  EXPECT_EQ(test::read_file(dir / "s.json"), "{\"a\": 1}\n");
  EXPECT_EQ(listing(dir).size(), 2u);
  fs::remove_all(dir);
}

TEST(ImageIo, ReadErrorsNameTheFile) {
  auto dir = test::temp_dir("readerr");
  expect_input_error([&] { read_image(dir / "nope.exr"); }, {"nope.exr", "No such file"});
  expect_input_error([&] { read_image(dir); }, {dir.string(), "folder"});

  test::write_file(dir / "empty.exr", "");
  expect_input_error([&] { read_image(dir / "empty.exr"); }, {"empty.exr", "empty"});

  test::write_file(dir / "junk.png", "this is not an image");
  expect_input_error([&] { read_image(dir / "junk.png"); }, {"junk.png", "cannot decode"});

  // Valid EXR magic, garbage after it.
  test::write_file(dir / "magic.exr", std::string("\x76\x2f\x31\x01", 4) + std::string(64, '\x07'));
  expect_input_error([&] { read_image(dir / "magic.exr"); }, {"magic.exr", "EXR"});

  // A real EXR cut in half.
  Image big = make_image(64, 64, true);
  for (size_t i = 0; i < big.rgb.size(); ++i) big.rgb[i] = float(i % 97) * 0.37f;
  write_image(dir / "full.exr", big, 0.0);
  std::string bytes = test::read_file(dir / "full.exr");
  test::write_file(dir / "cut.exr", bytes.substr(0, bytes.size() / 2));
  expect_input_error([&] { read_image(dir / "cut.exr"); }, {"cut.exr", "EXR"});
  fs::remove_all(dir);
}
