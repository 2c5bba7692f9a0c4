#pragma once
// The blackbody swatch strip: one swatch per temperature, left to right, each the
// seed-normalised colour (largest channel 1) display-encoded as sRGB, with its
// temperature written underneath. The picture a person checks first.
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <vector>

namespace pyrolume::color {

struct SwatchStrip {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // 8-bit sRGB, row-major, top row first
};

// At most this many swatches (one pixel wide each at the limit).
inline constexpr int kMaxSwatches = 16384;

// Throws std::invalid_argument for an empty list, more than kMaxSwatches
// temperatures, or a bad observer/adapt_to_k.
SwatchStrip render_swatch_strip(const std::vector<double>& temperatures_k, int observer = 2,
                                std::optional<double> adapt_to_k = std::nullopt);

// Encodes the strip as PNG into `os` (the caller picks the file: the CLI
// writes it through write_file_atomic). Throws std::runtime_error if the
// encoder fails.
void encode_swatch_strip_png(std::ostream& os, const SwatchStrip& strip);

}  // namespace pyrolume::color
