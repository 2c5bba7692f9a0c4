#include "image/ImageIo.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfIntAttribute.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <stb_image.h>
#include <stb_image_write.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <new>
#include <ostream>
#include <string>
#include <vector>

#include "image/AtomicFile.h"
#include "image/DisplayTransform.h"
#include "shared/view_transform.h"
#include "util/Error.h"
#include "util/InputFile.h"
#include "util/Memory.h"

namespace pyrolume {

namespace fs = std::filesystem;

float srgb_encode(float linear) { return display::view_srgb_oetf(linear); }

float srgb_decode(float v) {
  if (v <= 0.04045f) return v / 12.92f;
  return std::pow((v + 0.055f) / 1.055f, 2.4f);
}

unsigned char srgb_encode_u8(float linear, double exposure_stops) {
  float scaled = float(double(linear) * std::exp2(exposure_stops));
  return static_cast<unsigned char>(std::lround(255.0f * srgb_encode(scaled)));
}

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

namespace {

// OpenEXR messages can span lines; the CLI prints errors as one line.
std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

// OpenEXR output stream over the temp file's std::ostream, so the EXR goes through
// the same atomic path as every other output. Throwing here is caught by OpenEXR
// only in ~OutputFile; the stream's failbit still reports it afterwards.
class StdOStreamAdaptor : public Imf::OStream {
 public:
  explicit StdOStreamAdaptor(std::ostream& os) : Imf::OStream("exr output"), os_(os) {}
  void write(const char c[], int n) override {
    os_.write(c, n);
    if (!os_) throw std::runtime_error(std::string("write failed: ") + std::strerror(errno));
  }
  uint64_t tellp() override { return uint64_t(os_.tellp()); }
  void seekp(uint64_t pos) override {
    os_.seekp(std::streamoff(pos));
    if (!os_) throw std::runtime_error("seek failed");
  }

 private:
  std::ostream& os_;
};

// The AOV channels (docs/compositing.md "AOVs"): layer.channel, the Aovs
// vector they live in, its floats per pixel and the channel's place there.
struct AovChannel {
  const char* name;
  std::vector<float> Aovs::*layer;
  int stride, offset;
};
constexpr AovChannel kAovChannels[] = {
    {"emission.R", &Aovs::emission, 3, 0},     {"emission.G", &Aovs::emission, 3, 1},
    {"emission.B", &Aovs::emission, 3, 2},     {"scatter.R", &Aovs::scatter, 3, 0},
    {"scatter.G", &Aovs::scatter, 3, 1},       {"scatter.B", &Aovs::scatter, 3, 2},
    {"surface.R", &Aovs::surface, 3, 0},       {"surface.G", &Aovs::surface, 3, 1},
    {"surface.B", &Aovs::surface, 3, 2},       {"background.R", &Aovs::background, 3, 0},
    {"background.G", &Aovs::background, 3, 1}, {"background.B", &Aovs::background, 3, 2},
    {"albedo.R", &Aovs::albedo, 3, 0},         {"albedo.G", &Aovs::albedo, 3, 1},
    {"albedo.B", &Aovs::albedo, 3, 2},         {"normal.X", &Aovs::normal, 3, 0},
    {"normal.Y", &Aovs::normal, 3, 1},         {"normal.Z", &Aovs::normal, 3, 2},
    {"depth.Z", &Aovs::depth, 1, 0},
};
constexpr int kAovFloats = 19;  // per pixel, all layers
// The denoiser's guide: written with the AOVs by renders that have it; a file
// from before it has the AOVs without it (all four channels or none).
constexpr AovChannel kGuideChannels[] = {
    {"guide.R", &Aovs::guide, 3, 0},
    {"guide.G", &Aovs::guide, 3, 1},
    {"guide.B", &Aovs::guide, 3, 2},
    {"guide.A", &Aovs::guide_alpha, 1, 0},
};
constexpr int kGuideFloats = 4;

// The AOV channels an image holds: the AOVs, then the guide when it has one.
std::vector<AovChannel> aov_channels(bool aovs, bool guide) {
  std::vector<AovChannel> v;
  if (aovs) v.assign(std::begin(kAovChannels), std::end(kAovChannels));
  if (aovs && guide) v.insert(v.end(), std::begin(kGuideChannels), std::end(kGuideChannels));
  return v;
}

void write_exr(std::ostream& os, const Image& img) {
  Imf::Header header(img.width, img.height);
  header.compression() = Imf::ZIP_COMPRESSION;  // lossless: compare must see the exact floats
  if (img.spp > 0) header.insert("spp", Imf::IntAttribute(img.spp));
  if (img.spp_target > 0) header.insert("spp_target", Imf::IntAttribute(img.spp_target));
  const char* names[3] = {"R", "G", "B"};
  const char* var_names[3] = {"variance.R", "variance.G", "variance.B"};
  for (const char* n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
  if (img.has_variance())
    for (const char* n : var_names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
  if (img.has_alpha()) header.channels().insert("A", Imf::Channel(Imf::FLOAT));
  const std::vector<AovChannel> aov_out = aov_channels(img.has_aovs(), img.aovs.has_guide());
  for (const AovChannel& a : aov_out) header.channels().insert(a.name, Imf::Channel(Imf::FLOAT));

  Imf::FrameBuffer fb;
  const size_t xs = 3 * sizeof(float), ys = xs * size_t(img.width);
  for (int c = 0; c < 3; ++c) {
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(img.rgb.data() + c), xs, ys));
    if (img.has_variance())
      fb.insert(var_names[c], Imf::Slice(Imf::FLOAT, (char*)(img.variance.data() + c), xs, ys));
  }
  if (img.has_alpha())
    fb.insert("A", Imf::Slice(Imf::FLOAT, (char*)img.alpha.data(), sizeof(float), sizeof(float) * size_t(img.width)));
  for (const AovChannel& a : aov_out) {
    const std::vector<float>& layer = img.aovs.*a.layer;
    const size_t axs = size_t(a.stride) * sizeof(float);
    fb.insert(a.name, Imf::Slice(Imf::FLOAT, (char*)(layer.data() + a.offset), axs, axs * size_t(img.width)));
  }
  StdOStreamAdaptor stream(os);
  Imf::OutputFile out(stream, header);
  out.setFrameBuffer(fb);
  out.writePixels(img.height);
}

// With film.transparent, RGBA with straight alpha, as PNG defines it: the
// colour is RGB/A through the view transform (0 where A is 0).
void write_png(std::ostream& os, const Image& img, double exposure_stops, ViewTransform view) {
  auto sink = [](void* ctx, void* data, int size) { static_cast<std::ostream*>(ctx)->write((const char*)data, size); };
  if (!(img.transparent && img.has_alpha())) {
    const std::vector<unsigned char> bytes = display_rgb8(img, exposure_stops, view);
    if (!stbi_write_png_to_func(sink, &os, img.width, img.height, 3, bytes.data(), img.width * 3))
      throw std::runtime_error("PNG encoding failed");
    return;
  }
  Image straight = make_image(img.width, img.height);
  for (size_t i = 0; i < img.pixel_count(); ++i) {
    const float a = img.alpha[i];
    for (int c = 0; c < 3; ++c) straight.rgb[i * 3 + c] = a > 1e-6f ? img.rgb[i * 3 + c] / a : 0.0f;
  }
  const std::vector<unsigned char> rgb = display_rgb8(straight, exposure_stops, view);
  std::vector<unsigned char> rgba(img.pixel_count() * 4);
  for (size_t i = 0; i < img.pixel_count(); ++i) {
    for (int c = 0; c < 3; ++c) rgba[i * 4 + c] = rgb[i * 3 + c];
    rgba[i * 4 + 3] = (unsigned char)std::lround(std::clamp(img.alpha[i], 0.0f, 1.0f) * 255.0f);
  }
  if (!stbi_write_png_to_func(sink, &os, img.width, img.height, 4, rgba.data(), img.width * 4))
    throw std::runtime_error("PNG encoding failed");
}

// OpenEXR input over the bytes read_image already holds, so the header checks
// below and OpenEXR see the same data.
class MemoryIStream : public Imf::IStream {
 public:
  MemoryIStream(const std::vector<unsigned char>& bytes, const std::string& name)
      : Imf::IStream(name.c_str()), bytes_(bytes) {}
  bool read(char c[], int n) override {
    if (n < 0 || uint64_t(n) > bytes_.size() - pos_) throw std::runtime_error("early end of file");
    std::memcpy(c, bytes_.data() + pos_, size_t(n));
    pos_ += uint64_t(n);
    return pos_ < bytes_.size();
  }
  uint64_t tellg() override { return pos_; }
  void seekg(uint64_t pos) override {
    if (pos > bytes_.size()) throw std::runtime_error("seek past the end of the file");
    pos_ = pos;
  }

 private:
  const std::vector<unsigned char>& bytes_;
  uint64_t pos_ = 0;
};

// Limits on what an EXR header may ask for, checked before OpenEXR allocates
// by it (its InputFile constructor sizes line buffers and the chunk offset
// table from the header, and some attributes size arrays from their own
// fields). Generous for any real image; docs/robustness.md lists them.
constexpr int64_t kExrMaxPixels = int64_t(1) << 28;          // 16384 x 16384
constexpr int64_t kExrMaxSide = int64_t(1) << 20;
constexpr uint64_t kExrMaxChunkBytes = uint64_t(1) << 28;   // one scanline block or tile, decoded

// Walks the EXR header(s): every attribute's size within the file, the
// preview image and string vectors consistent with their sizes, and from
// dataWindow, channels, compression and tiles: the image size, the bytes one
// chunk decodes to and the offset table the file must hold.
void check_exr_header(const std::vector<unsigned char>& b, const std::string& name) {
  auto fail = [&](const std::string& why) { return input_error(name, "", "corrupt EXR: " + why); };
  size_t p = 8;
  if (b.size() < p) throw fail("truncated header");
  uint32_t version;
  std::memcpy(&version, b.data() + 4, 4);
  const bool tiled_flag = version & 0x200, multipart = version & 0x1000;
  auto i32 = [&](size_t at) {
    int32_t v;
    std::memcpy(&v, b.data() + at, 4);
    return v;
  };
  auto cstring = [&](const char* what) {
    const size_t start = p;
    while (p < b.size() && b[p] != 0) ++p;
    if (p >= b.size()) throw fail(std::string("unterminated ") + what);
    return std::string(reinterpret_cast<const char*>(b.data() + start), p++ - start);
  };
  uint64_t table_entries = 0;
  for (int part = 0;; ++part) {
    if (p >= b.size()) throw fail("truncated header");
    if (multipart && b[p] == 0) break;  // the empty header ends the list
    bool have_dw = false, have_channels = false, tiled = tiled_flag && !multipart;
    int64_t x0 = 0, y0 = 0, x1 = -1, y1 = -1;
    uint64_t pixel_bytes = 0;
    int compression = 0;
    uint32_t tw = 0, th = 0, level_mode = 0;
    for (;;) {
      const std::string attr = cstring("attribute name");
      if (attr.empty()) break;
      const std::string type = cstring("attribute type");
      if (b.size() - p < 4) throw fail("truncated attribute \"" + attr + "\"");
      const int32_t size = i32(p);
      p += 4;
      if (size < 0 || uint64_t(size) > b.size() - p)
        throw fail("attribute \"" + attr + "\" claims " + std::to_string(size) + " bytes, past the end of the file");
      const size_t v = p, end = p + size_t(size);
      if (type == "preview") {
        // PreviewImage: width, height, then 4 bytes per pixel.
        if (size < 8) throw fail("preview attribute too short");
        const int64_t w = uint32_t(i32(v)), h = uint32_t(i32(v + 4));
        if (w * h * 4 != int64_t(size) - 8) throw fail("preview image size does not match its attribute");
      } else if (type == "stringvector") {
        for (size_t q = v; q < end;) {
          if (end - q < 4) throw fail("string vector attribute \"" + attr + "\" truncated");
          const int32_t n = i32(q);
          q += 4;
          if (n < 0 || size_t(n) > end - q) throw fail("string vector attribute \"" + attr + "\" overruns its size");
          q += size_t(n);
        }
      } else if (attr == "dataWindow" && type == "box2i" && size == 16) {
        x0 = i32(v), y0 = i32(v + 4), x1 = i32(v + 8), y1 = i32(v + 12);
        have_dw = true;
      } else if (attr == "compression" && type == "compression" && size == 1) {
        compression = b[v];
      } else if (attr == "tiles" && type == "tiledesc" && size == 9) {
        tw = uint32_t(i32(v)), th = uint32_t(i32(v + 4)), level_mode = b[v + 8] & 0x0f;
        tiled = true;
      } else if (attr == "channels" && type == "chlist") {
        // name\0, int32 pixel type, 4 bytes, int32 x and y sampling; "\0" ends it.
        have_channels = true;
        for (size_t q = v; q < end;) {
          if (b[q] == 0) break;
          while (q < end && b[q] != 0) ++q;
          if (end - q < 17) throw fail("channel list truncated");
          const int32_t t = i32(q + 1);
          pixel_bytes += t == 1 ? 2 : 4;  // HALF, else UINT / FLOAT
          q += 17;
        }
      }
      p = end;
    }
    if (!have_dw || !have_channels) throw fail("header lacks dataWindow or channels");
    const int64_t w = x1 - x0 + 1, h = y1 - y0 + 1;
    if (w < 1 || h < 1 || w > kExrMaxSide || h > kExrMaxSide || w * h > kExrMaxPixels)
      throw fail("data window " + std::to_string(w) + " x " + std::to_string(h) + " is empty or larger than " +
                 std::to_string(kExrMaxPixels) + " pixels");
    if (tiled) {
      if (tw < 1 || th < 1 || uint64_t(tw) * th * std::max<uint64_t>(pixel_bytes, 1) > kExrMaxChunkBytes)
        throw fail("tile size " + std::to_string(tw) + " x " + std::to_string(th) + " is invalid or too large");
      // Tiles of every level (mip or rip levels rounded down): one offset each.
      const auto tiles = [&](int64_t lw, int64_t lh) { return uint64_t((lw + tw - 1) / tw) * ((lh + th - 1) / th); };
      int lx = 1, ly = 1;
      if (level_mode != 0)
        while ((w >> lx) > 0 || (h >> lx) > 0) ++lx;
      if (level_mode == 2) ly = lx;  // ripmap: every x level by every y level
      for (int a = 0; a < lx; ++a)
        for (int c = 0; c < (level_mode == 2 ? ly : 1); ++c)
          table_entries += tiles(std::max<int64_t>(w >> a, 1), std::max<int64_t>(h >> (level_mode == 2 ? c : a), 1));
    } else {
      static const int lines[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
      const int per_chunk = compression >= 0 && compression < 10 ? lines[compression] : 1;
      if (uint64_t(w) * pixel_bytes * uint64_t(per_chunk) > kExrMaxChunkBytes)
        throw fail(std::to_string(w) + " pixels of " + std::to_string(pixel_bytes) +
                   " bytes per scanline block of " + std::to_string(per_chunk) + " lines is too large");
      table_entries += uint64_t((h + per_chunk - 1) / per_chunk);
    }
    if (!multipart) break;
  }
  if (table_entries * 8 > b.size() - std::min<size_t>(p, b.size()))
    throw fail("the file is too short for the " + std::to_string(table_entries) + " chunks its header describes");
}

Image read_exr(const fs::path& file, const std::vector<unsigned char>& bytes) {
  check_exr_header(bytes, file.string());
  MemoryIStream stream(bytes, file.string());
  Imf::InputFile in(stream);
  const Imath::Box2i dw = in.header().dataWindow();
  const Imf::ChannelList& ch = in.header().channels();
  auto has = [&](const char* n) { return ch.findChannel(n) != nullptr; };

  const char* names[3] = {"R", "G", "B"};
  const char* var_names[3] = {"variance.R", "variance.G", "variance.B"};
  const bool alpha = has("A");
  bool rgb_any = has("R") || has("G") || has("B");
  bool gray = !rgb_any && has("Y");
  if (!rgb_any && !gray) throw input_error(file.string(), "", "EXR has no R, G, B or Y channel");
  int var_count = int(has(var_names[0])) + int(has(var_names[1])) + int(has(var_names[2]));
  if (var_count != 0 && var_count != 3)
    throw input_error(file.string(), "", "EXR has only some of variance.R, variance.G, variance.B");
  // AOVs: all of them or none (image/Image.h Aovs).
  const char* aov_present = nullptr;
  const char* aov_missing = nullptr;
  for (const AovChannel& a : kAovChannels) (has(a.name) ? aov_present : aov_missing) = a.name;
  if (aov_present && aov_missing)
    throw input_error(file.string(), "",
                      std::string("EXR has some AOV channels (") + aov_present + ") but not " + aov_missing);
  const bool aovs = aov_present != nullptr;
  const char* guide_present = nullptr;
  const char* guide_missing = nullptr;
  for (const AovChannel& a : kGuideChannels) (has(a.name) ? guide_present : guide_missing) = a.name;
  if (guide_present && (guide_missing || !aovs))
    throw input_error(file.string(), "",
                      std::string("EXR has some guide channels (") + guide_present + ") but not " +
                          (guide_missing ? guide_missing : kAovChannels[0].name));
  const std::vector<AovChannel> aov_in = aov_channels(aovs, guide_present != nullptr);

  // Read in blocks of rows, growing the image as they decode: memory follows
  // the pixel data the file really holds, not what a corrupt header claims
  // (check_exr_header has bounded the window). Slice::Make addresses each
  // block by absolute data-window coordinates without out-of-range pointer
  // arithmetic.
  Image img;
  img.width = dw.max.x - dw.min.x + 1;
  img.height = dw.max.y - dw.min.y + 1;
  require_memory(file.string(), "", std::to_string(img.width) + " x " + std::to_string(img.height) + " pixels",
                 uint64_t(img.width) * uint64_t(img.height) * sizeof(float) *
                     ((var_count == 3 ? 6 : 3) + (alpha ? 1 : 0) + (aovs ? kAovFloats : 0) + (guide_present ? kGuideFloats : 0)));
  const size_t row_floats = size_t(img.width) * 3, xs = 3 * sizeof(float), ys = xs * size_t(img.width);
  const int rows_per_block = int(std::max<size_t>(1, (size_t(16) << 20) / ys));
  for (int y0 = 0; y0 < img.height; y0 += rows_per_block) {
    const int rows = std::min(rows_per_block, img.height - y0);
    img.rgb.resize(size_t(y0 + rows) * row_floats, 0.0f);
    if (var_count == 3) img.variance.resize(img.rgb.size(), 0.0f);
    if (alpha) img.alpha.resize(size_t(y0 + rows) * size_t(img.width), 0.0f);
    for (const AovChannel& a : aov_in) (img.aovs.*a.layer).resize(size_t(y0 + rows) * size_t(img.width) * a.stride, 0.0f);
    const Imath::Box2i block(Imath::V2i(dw.min.x, dw.min.y + y0), Imath::V2i(dw.max.x, dw.min.y + y0 + rows - 1));
    // A FrameBuffer maps each name once, so a Y-only file fills R and is copied to G, B.
    Imf::FrameBuffer fb;
    for (int c = 0; c < 3; ++c) {
      const size_t at = size_t(y0) * row_floats + size_t(c);
      if (!gray || c == 0)
        fb.insert(gray ? "Y" : names[c], Imf::Slice::Make(Imf::FLOAT, img.rgb.data() + at, block, xs, ys));
      if (var_count == 3)
        fb.insert(var_names[c], Imf::Slice::Make(Imf::FLOAT, img.variance.data() + at, block, xs, ys));
    }
    if (alpha)
      fb.insert("A", Imf::Slice::Make(Imf::FLOAT, img.alpha.data() + size_t(y0) * size_t(img.width), block,
                                      sizeof(float), sizeof(float) * size_t(img.width)));
    for (const AovChannel& a : aov_in) {
      std::vector<float>& layer = img.aovs.*a.layer;
      const size_t axs = size_t(a.stride) * sizeof(float);
      fb.insert(a.name, Imf::Slice::Make(Imf::FLOAT, layer.data() + size_t(y0) * size_t(img.width) * a.stride + a.offset,
                                         block, axs, axs * size_t(img.width)));
    }
    in.setFrameBuffer(fb);
    in.readPixels(block.min.y, block.max.y);
  }
  if (gray)
    for (size_t i = 0; i < img.rgb.size(); i += 3) img.rgb[i + 1] = img.rgb[i + 2] = img.rgb[i];
  if (auto* a = in.header().findTypedAttribute<Imf::IntAttribute>("spp")) img.spp = a->value();
  if (auto* a = in.header().findTypedAttribute<Imf::IntAttribute>("spp_target")) img.spp_target = a->value();
  return img;
}

Image read_stb(const fs::path& file, const std::vector<unsigned char>& bytes) {
  const auto* data = bytes.data();
  const int len = int(bytes.size());
  int w = 0, h = 0, n = 0;
  Image img;
  auto fail = [&] {
    const char* why = stbi_failure_reason();
    return input_error(file.string(), "", std::string("cannot decode image: ") + (why ? why : "unknown format"));
  };
  // stb_image decodes a truncated file as if the missing bytes were zero, so
  // a 61-byte TGA header claiming 20000 x 20000 "decodes" to gigabytes (found
  // by fuzz_image). Bound the size by the header first: no format stb reads
  // packs more than ~1000 pixels into a byte (zlib's limit), so 4096 per byte
  // of file leaves any real image through.
  if (stbi_info_from_memory(data, len, &w, &h, &n)) {
    const int64_t pixels = int64_t(w) * int64_t(h);
    if (w < 1 || h < 1 || pixels > kExrMaxPixels || pixels > int64_t(bytes.size()) * 4096)
      throw input_error(file.string(), "",
                        "image header claims " + std::to_string(w) + " x " + std::to_string(h) + " pixels for a " +
                            std::to_string(bytes.size()) + "-byte file (corrupt or truncated)");
    // The decoded pixels as stb returns them (up to 4 floats each) and as floats here.
    require_memory(file.string(), "", std::to_string(w) + " x " + std::to_string(h) + " pixels",
                   uint64_t(pixels) * (3 + 4) * sizeof(float));
  }
  if (stbi_is_hdr_from_memory(data, len)) {
    float* px = stbi_loadf_from_memory(data, len, &w, &h, &n, 3);
    if (!px) throw fail();
    img = make_image(w, h);
    std::copy(px, px + img.rgb.size(), img.rgb.begin());
    stbi_image_free(px);
  } else if (stbi_is_16_bit_from_memory(data, len)) {
    stbi_us* px = stbi_load_16_from_memory(data, len, &w, &h, &n, 3);
    if (!px) throw fail();
    img = make_image(w, h);
    for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = srgb_decode(px[i] / 65535.0f);
    stbi_image_free(px);
  } else {
    stbi_uc* px = stbi_load_from_memory(data, len, &w, &h, &n, 3);
    if (!px) throw fail();
    img = make_image(w, h);
    for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = srgb_decode(px[i] / 255.0f);
    stbi_image_free(px);
  }
  return img;
}

}  // namespace

void write_image(const fs::path& file, const Image& img, double exposure_stops, ViewTransform view) {
  const std::string ext = lower_extension(file);
  if (ext != ".exr" && ext != ".png")
    throw input_error(file.string(), "", "unknown image extension '" + file.extension().string() + "' (use .exr or .png)");
  if (img.width <= 0 || img.height <= 0 || img.rgb.size() != img.pixel_count() * 3)
    throw std::logic_error("write_image: image size does not match its pixel data");
  if (img.has_variance() && img.variance.size() != img.rgb.size())
    throw std::logic_error("write_image: variance size does not match the image");
  for (const AovChannel& a : aov_channels(img.has_aovs(), img.aovs.has_guide()))
      if ((img.aovs.*a.layer).size() != img.pixel_count() * size_t(a.stride))
        throw std::logic_error(std::string("write_image: AOV ") + a.name + " size does not match the image");

  try {
    write_file_atomic(file, [&](std::ostream& os) {
      if (ext == ".exr")
        write_exr(os, img);
      else
        write_png(os, img, exposure_stops, view);
    });
  } catch (const InputError&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw;
  } catch (const std::exception& e) {  // OpenEXR (Iex) and stb encoding failures
    throw input_error(file.string(), "", one_line(e.what()));
  }
}

Image read_image(const fs::path& file) {
  const std::string name = file.string();
  std::error_code ec;
  if (fs::is_directory(file, ec)) throw input_error(name, "", "is a folder, not an image");
  std::vector<unsigned char> bytes;
  {
    const std::string text = read_input_file(file, kMaxImageBytes, "image", 2.0);  // and its copy below
    bytes.assign(text.begin(), text.end());
  }
  if (bytes.empty()) throw input_error(name, "", "file is empty");

  // EXR magic number 20000630 (little-endian 76 2f 31 01).
  const bool exr = bytes.size() >= 4 && bytes[0] == 0x76 && bytes[1] == 0x2f && bytes[2] == 0x31 && bytes[3] == 0x01;
  try {
    return exr ? read_exr(file, bytes) : read_stb(file, bytes);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {  // Iex from a corrupt or truncated EXR; bad_alloc from a bogus size
    throw input_error(name, "", "cannot read EXR: " + one_line(e.what()));
  }
}

}  // namespace pyrolume
