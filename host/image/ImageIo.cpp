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
#include <cstring>
#include <fstream>
#include <iterator>
#include <new>
#include <ostream>
#include <string>

#include "image/AtomicFile.h"
#include "util/Error.h"

namespace pyrolume {

namespace fs = std::filesystem;

float srgb_encode(float linear) {
  if (!(linear > 0.0f)) return 0.0f;  // negatives and NaN
  if (linear >= 1.0f) return 1.0f;
  if (linear <= 0.0031308f) return 12.92f * linear;
  return 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

float srgb_decode(float v) {
  if (v <= 0.04045f) return v / 12.92f;
  return std::pow((v + 0.055f) / 1.055f, 2.4f);
}

unsigned char srgb_encode_u8(float linear, double exposure_stops) {
  float scaled = float(double(linear) * std::exp2(exposure_stops));
  return static_cast<unsigned char>(std::lround(255.0f * srgb_encode(scaled)));
}

namespace {

std::string lower_extension(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

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

  Imf::FrameBuffer fb;
  const size_t xs = 3 * sizeof(float), ys = xs * size_t(img.width);
  for (int c = 0; c < 3; ++c) {
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)(img.rgb.data() + c), xs, ys));
    if (img.has_variance())
      fb.insert(var_names[c], Imf::Slice(Imf::FLOAT, (char*)(img.variance.data() + c), xs, ys));
  }
  StdOStreamAdaptor stream(os);
  Imf::OutputFile out(stream, header);
  out.setFrameBuffer(fb);
  out.writePixels(img.height);
}

void write_png(std::ostream& os, const Image& img, double exposure_stops) {
  std::vector<unsigned char> bytes(img.rgb.size());
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = srgb_encode_u8(img.rgb[i], exposure_stops);
  auto sink = [](void* ctx, void* data, int size) { static_cast<std::ostream*>(ctx)->write((const char*)data, size); };
  if (!stbi_write_png_to_func(sink, &os, img.width, img.height, 3, bytes.data(), img.width * 3))
    throw std::runtime_error("PNG encoding failed");
}

Image read_exr(const fs::path& file) {
  Imf::InputFile in(file.c_str());
  const Imath::Box2i dw = in.header().dataWindow();
  Image img = make_image(dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1);
  const Imf::ChannelList& ch = in.header().channels();
  auto has = [&](const char* n) { return ch.findChannel(n) != nullptr; };

  const char* names[3] = {"R", "G", "B"};
  const char* var_names[3] = {"variance.R", "variance.G", "variance.B"};
  bool rgb_any = has("R") || has("G") || has("B");
  bool gray = !rgb_any && has("Y");
  if (!rgb_any && !gray) throw input_error(file.string(), "", "EXR has no R, G, B or Y channel");
  int var_count = int(has(var_names[0])) + int(has(var_names[1])) + int(has(var_names[2]));
  if (var_count != 0 && var_count != 3)
    throw input_error(file.string(), "", "EXR has only some of variance.R, variance.G, variance.B");
  if (var_count == 3) img.variance.assign(img.rgb.size(), 0.0f);

  // Slices are addressed by absolute data-window coordinates (OpenEXR convention),
  // so the base pointer is shifted back by the window origin.
  const size_t xs = 3 * sizeof(float), ys = xs * size_t(img.width);
  auto base = [&](std::vector<float>& v, int c) {
    return (char*)(v.data() + c) - ptrdiff_t(dw.min.x) * ptrdiff_t(xs) - ptrdiff_t(dw.min.y) * ptrdiff_t(ys);
  };
  // A FrameBuffer maps each name once, so a Y-only file fills R and is copied to G, B.
  Imf::FrameBuffer fb;
  for (int c = 0; c < 3; ++c) {
    if (!gray || c == 0) fb.insert(gray ? "Y" : names[c], Imf::Slice(Imf::FLOAT, base(img.rgb, c), xs, ys, 1, 1, 0.0));
    if (var_count == 3) fb.insert(var_names[c], Imf::Slice(Imf::FLOAT, base(img.variance, c), xs, ys, 1, 1, 0.0));
  }
  in.setFrameBuffer(fb);
  in.readPixels(dw.min.y, dw.max.y);
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

void write_image(const fs::path& file, const Image& img, double exposure_stops) {
  const std::string ext = lower_extension(file);
  if (ext != ".exr" && ext != ".png")
    throw input_error(file.string(), "", "unknown image extension '" + file.extension().string() + "' (use .exr or .png)");
  if (img.width <= 0 || img.height <= 0 || img.rgb.size() != img.pixel_count() * 3)
    throw std::logic_error("write_image: image size does not match its pixel data");
  if (img.has_variance() && img.variance.size() != img.rgb.size())
    throw std::logic_error("write_image: variance size does not match the image");

  try {
    write_file_atomic(file, [&](std::ostream& os) {
      if (ext == ".exr")
        write_exr(os, img);
      else
        write_png(os, img, exposure_stops);
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
  std::ifstream in(file, std::ios::binary);
  if (!in) throw input_error(name, "", std::string("cannot open: ") + std::strerror(errno));
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw input_error(name, "", std::string("cannot read: ") + std::strerror(errno));
  if (bytes.empty()) throw input_error(name, "", "file is empty");

  // EXR magic number 20000630 (little-endian 76 2f 31 01).
  const bool exr = bytes.size() >= 4 && bytes[0] == 0x76 && bytes[1] == 0x2f && bytes[2] == 0x31 && bytes[3] == 0x01;
  try {
    return exr ? read_exr(file) : read_stb(file, bytes);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {  // Iex from a corrupt or truncated EXR; bad_alloc from a bogus size
    throw input_error(name, "", "cannot read EXR: " + one_line(e.what()));
  }
}

}  // namespace pyrolume
