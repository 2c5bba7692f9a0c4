#include "color/SwatchStrip.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <ostream>
#include <stdexcept>
#include <string>

// stb_image_write's implementation is compiled once, in host/image/StbImpl.cpp.
#include <stb_image_write.h>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#include <stb_easy_font.h>
#pragma GCC diagnostic pop

#include "color/Blackbody.h"
#include "color/ColorSpace.h"

namespace pyrolume::color {
namespace {

constexpr int kSwatchHeight = 96;
constexpr int kMaxSwatchWidth = 96;
constexpr int kLabelBand = 30;  // grey band under the swatches for the labels
constexpr int kFontScale = 2;   // stb_easy_font glyphs are ~7 px tall; draw them at 2x
constexpr uint8_t kBandGrey = 40, kTextGrey = 235;

std::string label_for(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g K", t);
  return buf;
}

int label_width_px(const std::string& text) {
  return stb_easy_font_width(const_cast<char*>(text.c_str())) * kFontScale;
}

void fill(SwatchStrip& s, int x0, int y0, int x1, int y1, uint8_t r, uint8_t g, uint8_t b) {
  x0 = std::max(x0, 0), y0 = std::max(y0, 0), x1 = std::min(x1, s.width), y1 = std::min(y1, s.height);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      uint8_t* p = &s.rgb[3 * (size_t(y) * s.width + x)];
      p[0] = r, p[1] = g, p[2] = b;
    }
}

// stb_easy_font emits axis-aligned quads (4 vertices of x, y, z floats + 4 colour
// bytes); filling each quad's box rasterises the text without a GPU.
void draw_text(SwatchStrip& s, int x, int y, const std::string& text) {
  std::vector<char> vbuf(text.size() * 300 + 256);  // stb_easy_font: ~270 bytes per character
  unsigned char colour[4] = {255, 255, 255, 255};
  const int quads = stb_easy_font_print(0, 0, const_cast<char*>(text.c_str()), colour, vbuf.data(), int(vbuf.size()));
  for (int q = 0; q < quads; ++q) {
    const float* v0 = reinterpret_cast<const float*>(vbuf.data() + (4 * q + 0) * 16);
    const float* v2 = reinterpret_cast<const float*>(vbuf.data() + (4 * q + 2) * 16);
    const int x0 = x + int(std::floor(std::min(v0[0], v2[0]) * kFontScale));
    const int x1 = x + int(std::ceil(std::max(v0[0], v2[0]) * kFontScale));
    const int y0 = y + int(std::floor(std::min(v0[1], v2[1]) * kFontScale));
    const int y1 = y + int(std::ceil(std::max(v0[1], v2[1]) * kFontScale));
    fill(s, x0, y0, x1, y1, kTextGrey, kTextGrey, kTextGrey);
  }
}

}  // namespace

SwatchStrip render_swatch_strip(const std::vector<double>& temperatures_k, int observer,
                                std::optional<double> adapt_to_k) {
  const int n = int(std::min<size_t>(temperatures_k.size(), size_t(kMaxSwatches) + 1));
  if (n == 0) throw std::invalid_argument("swatch strip: no temperatures");
  if (n > kMaxSwatches)
    throw std::invalid_argument("swatch strip: " + std::to_string(temperatures_k.size()) +
                                " temperatures, at most " + std::to_string(kMaxSwatches));

  // Swatches shrink (to 1 px) so the strip stays under 16384 px wide; labels
  // go on every k-th swatch so that neighbouring labels never overlap.
  const int w = std::clamp(kMaxSwatches / n, 1, kMaxSwatchWidth);
  int widest = 0;
  for (double t : temperatures_k) widest = std::max(widest, label_width_px(label_for(t)));
  const int every = std::max(1, (widest + 8 + w - 1) / w);

  SwatchStrip s;
  s.width = std::max(n * w, widest + 4);
  s.height = kSwatchHeight + kLabelBand;
  s.rgb.assign(size_t(s.width) * s.height * 3, 0);
  fill(s, 0, kSwatchHeight, s.width, s.height, kBandGrey, kBandGrey, kBandGrey);

  for (int i = 0; i < n; ++i) {
    const glm::dvec3 c = blackbody_rgb(temperatures_k[i], BlackbodyMode::Seed, observer, adapt_to_k);
    auto enc = [](double v) { return uint8_t(std::lround(255.0 * srgb_encode(v))); };
    fill(s, i * w, 0, (i + 1) * w, kSwatchHeight, enc(c.r), enc(c.g), enc(c.b));
    if (i % every) continue;
    const std::string label = label_for(temperatures_k[i]);
    const int lw = label_width_px(label);
    // Centre under its swatch when it fits, else start at the swatch with a tick.
    int x = i * w + (w - lw) / 2;
    if (lw > w) {
      x = i * w;
      fill(s, i * w + w / 2, kSwatchHeight, i * w + w / 2 + 2, kSwatchHeight + 4, kTextGrey, kTextGrey, kTextGrey);
    }
    x = std::clamp(x, 2, std::max(2, s.width - lw - 2));
    draw_text(s, x, kSwatchHeight + 8, label);
  }
  return s;
}

namespace {
void write_to_stream(void* context, void* data, int size) {
  static_cast<std::ostream*>(context)->write(static_cast<const char*>(data), size);
}
}  // namespace

void encode_swatch_strip_png(std::ostream& os, const SwatchStrip& strip) {
  if (!stbi_write_png_to_func(write_to_stream, &os, strip.width, strip.height, 3, strip.rgb.data(), strip.width * 3))
    throw std::runtime_error("cannot encode the swatch strip as PNG");
}

}  // namespace pyrolume::color
