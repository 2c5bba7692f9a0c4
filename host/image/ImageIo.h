#pragma once
// Image files: EXR (linear float, the lossless format every render and compare
// uses) and PNG (8-bit sRGB for looking at). Errors are InputError "FILE: REASON".
#include <filesystem>
#include <string>

#include "image/Image.h"
#include "scene/Scene.h"

namespace pyrolume {

// sRGB OETF and its inverse, IEC 61966-2-1 (the piecewise curve, not gamma 2.2):
//   encode: 12.92·L for L ≤ 0.0031308, else 1.055·L^(1/2.4) − 0.055
//   decode: V/12.92 for V ≤ 0.04045, else ((V + 0.055)/1.055)^2.4
// encode clamps to [0, 1] first (NaN → 0); decode expects V in [0, 1].
// encode is view_srgb_oetf of shaders/shared/view_transform.h.
float srgb_encode(float linear);
float srgb_decode(float encoded);

// linear → 8-bit sRGB after scaling by 2^exposure_stops: round(255·encode(L·2^e)).
unsigned char srgb_encode_u8(float linear, double exposure_stops = 0.0);

// Chooses the format by extension (case-insensitive):
//   .exr  float32, ZIP, channels R, G, B (+ variance.R/G/B when img has variance,
//         + A when img has alpha; + emission.R/G/B, scatter.R/G/B, surface.R/G/B,
//         background.R/G/B, albedo.R/G/B, normal.X/Y/Z, depth.Z when img has AOVs);
//         int header attributes "spp" / "spp_target" when img.spp / spp_target > 0;
//         linear, exposure NOT applied.
//   .png  8-bit sRGB RGB through exposure and `view` (image/DisplayTransform.h
//         display_rgb8), variance dropped; RGBA, straight alpha, when
//         img.transparent and img has alpha. Renders pass film.view; the default,
//         Standard, suits data such as textures (a plain sRGB encode).
// Atomic (see AtomicFile.h): a failure leaves no file at `file`.
// Unknown extension, empty image, or an I/O failure → InputError.
void write_image(const std::filesystem::path& file, const Image& img, double exposure_stops = 0.0,
                 ViewTransform view = ViewTransform::Standard);

// The file name's extension in lower case (".exr", ".png"): what chooses
// write_image's format, and what the CLI and the preview check outputs by.
std::string lower_extension(const std::filesystem::path& file);

// Reads by content, not by extension:
//   EXR: data window; R, G, B (missing ones read as 0); a Y-only file gives
//        R = G = B = Y; A when present; variance.R/G/B loaded when all three exist;
//        the AOV channels (above) when all of them exist; some of them only,
//        or some variance channels only, is an InputError naming the file and
//        the missing channel;
//        the "spp" / "spp_target" attributes when present.
//        Half and uint channels are converted to float.
//   PNG/JPG/BMP/TGA (via stb_image): sRGB decoded to linear (8- and 16-bit).
//   Radiance .hdr (via stb_image): already linear.
// Missing, unreadable or corrupt file → InputError naming the file and the reason.
Image read_image(const std::filesystem::path& file);

}  // namespace pyrolume
