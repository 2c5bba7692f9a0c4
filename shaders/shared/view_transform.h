// The view transforms: scene-linear radiance (already scaled by 2^exposure) ->
// sRGB-encoded display values in [0, 1]. One implementation, included by the
// PNG writer (host/image/DisplayTransform.cpp) and the preview's display shader
// (shaders/preview_display.comp), written in the common subset of GLSL and C++
// (shared/common.h): the C++ side gets GLM's vec3/mat3 and functions in
// pyrolume::display (not pyrolume::gpu, whose structs must stay free of vec3).
// docs/view-transform.md describes the transform and where its numbers come from.
#ifndef PYROLUME_VIEW_TRANSFORM_H
#define PYROLUME_VIEW_TRANSFORM_H

#include "shared/common.h"
#ifdef __cplusplus
namespace pyrolume::display {
using vec3 = glm::vec3;
using mat3 = glm::mat3;
using uint = uint32_t;
using glm::clamp;
using glm::dot;
using glm::exp2;
using glm::log2;
using glm::max;
using glm::min;
using glm::pow;
using glm::transpose;
#define VIEW_FN inline
#else
#define VIEW_FN
#endif

// film.view: which transform (DisplayConstants.view in the preview). The
// numbers are only this header's and the preview's; scene files use the names
// of host/scene/Scene.h (to_string(ViewTransform)).
PYRO_CONST uint VIEW_AGX = 0u;         // AgX, base contrast, sRGB display
PYRO_CONST uint VIEW_STANDARD = 1u;    // clip to [0, 1], sRGB OETF: the output before views existed
PYRO_CONST uint VIEW_AGX_PUNCHY = 2u;  // AgX with the "punchy" look (an ASC CDL on the sigmoid's output)
PYRO_CONST uint VIEW_FILMIC = 3u;      // a fit of Blender 3.4's Filmic, look None, sRGB display
PYRO_CONST uint VIEW_COUNT = 4u;

// AgX's log2 encoding spans AGX_EV_BELOW stops below to AGX_EV_ABOVE stops above
// middle grey (Blender 4's AgX: -10 to +6.5 EV around 0.18).
PYRO_CONST float AGX_MIDDLE_GREY = 0.18f;
PYRO_CONST float AGX_EV_BELOW = 10.0f;
PYRO_CONST float AGX_EV_ABOVE = 6.5f;
// The sigmoid's output is display-encoded with a pure 2.4 power: Blender's AgX
// pivots it at 0.18^(1/2.4), so middle grey decodes to (about) 0.18 again.
PYRO_CONST float AGX_DISPLAY_GAMMA = 2.4f;

// sRGB OETF, IEC 61966-2-1 (the piecewise curve, not a 2.2 power), clamped to
// [0, 1] first; negatives and NaN give 0. The one sRGB encode of display output
// (host/image/ImageIo.h srgb_encode is this function).
VIEW_FN float view_srgb_oetf(float L) {
  if (!(L > 0.0f)) return 0.0f;
  if (L >= 1.0f) return 1.0f;
  if (L <= 0.0031308f) return 12.92f * L;
  return 1.055f * pow(L, 1.0f / 2.4f) - 0.055f;
}

// Linear BT.709 (sRGB) primaries -> linear BT.2020, D65 on both sides: computed
// from the primaries' chromaticities (ITU-R BT.709-6, BT.2020-2) via XYZ. Rows
// sum to 1 (white stays white). AgX works in BT.2020 (Blender 4's AgX).
VIEW_FN mat3 view_bt709_to_bt2020() {
  return transpose(mat3(0.627403896f, 0.329283038f, 0.043313066f,
                        0.069097289f, 0.919540395f, 0.011362316f,
                        0.016391439f, 0.088013308f, 0.895595253f));
}
VIEW_FN mat3 view_bt2020_to_bt709() {
  return transpose(mat3(1.660491002f, -0.587641139f, -0.072849863f,
                        -0.124550475f, 1.132899897f, -0.008349423f,
                        -0.018150763f, -0.100578898f, 1.118729661f));
}

// AgX's inset matrix (Blender 4.0, in BT.2020): pulls every primary towards the
// achromatic axis, so that a very bright saturated colour desaturates on its way
// to white (the "path to white") instead of clipping per channel to a flat
// yellow or magenta. Rows sum to 1: greys stay grey.
VIEW_FN mat3 view_agx_inset() {
  return transpose(mat3(0.856627153f, 0.095121241f, 0.048251606f,
                        0.137318973f, 0.761241991f, 0.101439036f,
                        0.111898213f, 0.076799419f, 0.811302368f));
}
// AgX's outset matrix (Blender 4.0, in BT.2020): gives back part of the purity
// the inset took, after the sigmoid. Rows sum to 1.
VIEW_FN mat3 view_agx_outset() {
  return transpose(mat3(1.127100582f, -0.110606643f, -0.016493939f,
                        -0.141329763f, 1.157823702f, -0.016493939f,
                        -0.141329763f, -0.110606643f, 1.251936407f));
}

// The AgX base-contrast sigmoid on the normalised log2 value x in [0, 1]: the
// widely used 6th-order polynomial fit of it (B. Wrensch, "Minimal AgX
// implementation", iolite engine blog, 2023; mean squared error 3.7e-6),
// evaluated in Horner form. Increasing on [0, 1]; 0 -> -0.00232, 1 -> 0.99858.
VIEW_FN vec3 view_agx_sigmoid(vec3 x) {
  vec3 p = 15.5f * x - 40.14f;
  p = p * x + 31.96f;
  p = p * x - 6.868f;
  p = p * x + 0.4298f;
  p = p * x + 0.1191f;
  return p * x - 0.00232f;
}

// Non-finite and negative values become 0; huge values are capped so that the
// matrices cannot make Inf - Inf. (NaN fails every comparison in C++; GLSL
// does not promise IEEE NaN behaviour, but the renders never accumulate NaN:
// non-finite samples are recorded as 0.)
VIEW_FN float view_sanitize(float v) { return v > 0.0f ? min(v, 1.0e30f) : 0.0f; }

// AgX up to its sigmoid: scene-linear sRGB -> the sigmoid's display-encoded
// output, per channel of the inset BT.2020 space.
VIEW_FN vec3 view_agx_encoded(vec3 rgb) {
  vec3 c = vec3(view_sanitize(rgb.x), view_sanitize(rgb.y), view_sanitize(rgb.z));
  c = view_agx_inset() * (view_bt709_to_bt2020() * c);
  // log2 over [grey - EV_BELOW, grey + EV_ABOVE], normalised to [0, 1]; the
  // floor keeps log2 away from 0 (it lies far below the range anyway).
  const float lo = log2(AGX_MIDDLE_GREY) - AGX_EV_BELOW;
  const float range = AGX_EV_BELOW + AGX_EV_ABOVE;
  vec3 x = clamp((log2(max(c, 1.0e-10f)) - lo) / range, 0.0f, 1.0f);
  return view_agx_sigmoid(x);
}

// AgX after its sigmoid (or a look on the sigmoid's output): decode to linear,
// then the outset and back to BT.709 -> display-linear sRGB in [0, 1].
VIEW_FN vec3 view_agx_decode(vec3 encoded) {
  vec3 y = pow(max(encoded, 0.0f), vec3(AGX_DISPLAY_GAMMA));
  y = view_bt2020_to_bt709() * (view_agx_outset() * y);
  return clamp(y, 0.0f, 1.0f);  // the few out-of-gamut colours: clipped
}

// AgX: scene-linear sRGB -> display-linear sRGB in [0, 1].
VIEW_FN vec3 view_agx(vec3 rgb) { return view_agx_decode(view_agx_encoded(rgb)); }

// AgX's "punchy" look, as B. Wrensch's "Minimal AgX implementation" (iolite
// engine blog, 2023) gives it: an ASC CDL on the sigmoid's display-encoded
// output, before the decode. Slope 1 and offset 0, so only the power; then the
// CDL's saturation about the Rec.709-weighted luma of the powered value (the
// CDL's order: greys stay greys and go to g^1.35 exactly). Negative results
// of the saturation are clipped by view_agx_decode.
PYRO_CONST float AGX_PUNCHY_POWER = 1.35f;
PYRO_CONST float AGX_PUNCHY_SATURATION = 1.4f;
VIEW_FN vec3 view_agx_punchy_look(vec3 encoded) {
  vec3 v = pow(max(encoded, 0.0f), vec3(AGX_PUNCHY_POWER));
  float luma = dot(v, vec3(0.2126f, 0.7152f, 0.0722f));
  return vec3(luma) + AGX_PUNCHY_SATURATION * (v - vec3(luma));
}

// AgX with the punchy look: scene-linear sRGB -> display-linear sRGB in [0, 1].
VIEW_FN vec3 view_agx_punchy(vec3 rgb) { return view_agx_decode(view_agx_punchy_look(view_agx_encoded(rgb))); }

// Filmic: a formula fitted to what Blender 3.4's "Filmic" view (look None,
// sRGB display, exposure 0, gamma 1) writes through Image.save_render
// (docs/view-transform.md "Filmic": how it was measured, and its error: within
// 0.26 8-bit steps on greys, 1.41 on fire colours). Three stages:
// 1. highlight desaturation: once the largest channel passes about 11.5
//    (+6 stops over 0.18), the same linear amount is added to every channel,
//    a growing push towards white (Blender does this with a 3D LUT);
// 2. per channel, log2 over the 16.5 stops from 0.18 * 2^-10 to 0.18 * 2^6.5,
//    normalised to [0, 1] and clamped;
// 3. per channel, the base contrast curve: a degree-8 polynomial through
//    (0, 0) and (1, 1) whose output is already sRGB-encoded.
PYRO_CONST float FILMIC_LO = -12.473931188f;     // log2(0.18) - 10: the window's bottom
PYRO_CONST float FILMIC_HI = 4.026068812f;       // log2(0.18) + 6.5: display white
PYRO_CONST float FILMIC_BLACK = 0.00017578125f;  // 2^FILMIC_LO = 0.18 / 1024
PYRO_CONST float FILMIC_U_MAX = 12.526068812f;   // FILMIC_LO + 25: Blender's desaturation stage clips log2(max) here
// The desaturation's amount, in the log domain: d = log2(max channel) - U0
// (from max ~ 11.46 on), s = A d / (d + C) + B d, added = BLACK (2^s - 1).
PYRO_CONST float FILMIC_DESAT_U0 = 3.5180113f;
PYRO_CONST float FILMIC_DESAT_A = 6.5156213f;
PYRO_CONST float FILMIC_DESAT_C = 0.303063161f;
PYRO_CONST float FILMIC_DESAT_B = 2.08404467f;

// The base contrast curve on the normalised log2 value x in [0, 1] (Horner
// form; coefficients of x^1 .. x^8, which sum to 1): sRGB-encoded output,
// increasing on [0, 1].
VIEW_FN vec3 view_filmic_curve(vec3 x) {
  vec3 y = x * -85.5315807f + 342.530608f;
  y = y * x - 532.767131f;
  y = y * x + 403.987543f;
  y = y * x - 157.537002f;
  y = y * x + 33.039028f;
  y = y * x - 2.87575954f;
  y = y * x + 0.154294485f;
  return y * x;
}

// Filmic: scene-linear sRGB -> sRGB-ENCODED display values in [0, 1] (unlike
// view_agx, whose output is display-linear).
VIEW_FN vec3 view_filmic(vec3 rgb) {
  vec3 c = vec3(view_sanitize(rgb.x), view_sanitize(rgb.y), view_sanitize(rgb.z));
  // 1. Desaturation: depends on the largest channel only; 0 below the onset.
  float u = min(log2(max(max(max(c.x, c.y), c.z), 1.0e-10f)), FILMIC_U_MAX);
  float d = max(u - FILMIC_DESAT_U0, 0.0f);
  float s = FILMIC_DESAT_A * d / (d + FILMIC_DESAT_C) + FILMIC_DESAT_B * d;
  c = c + vec3(FILMIC_BLACK * (exp2(s) - 1.0f));
  // 2. The log window; 3. the curve.
  vec3 x = clamp((log2(max(c, 1.0e-10f)) - FILMIC_LO) / (FILMIC_HI - FILMIC_LO), 0.0f, 1.0f);
  return clamp(view_filmic_curve(x), 0.0f, 1.0f);
}

// The whole view: exposed scene-linear sRGB -> sRGB-encoded display values in [0, 1].
VIEW_FN vec3 view_display(vec3 exposed, uint view) {
  if (view == VIEW_FILMIC) return view_filmic(exposed);  // encoded already
  vec3 d = view == VIEW_STANDARD     ? exposed
           : view == VIEW_AGX_PUNCHY ? view_agx_punchy(exposed)
                                     : view_agx(exposed);
  return vec3(view_srgb_oetf(d.x), view_srgb_oetf(d.y), view_srgb_oetf(d.z));
}

#ifdef __cplusplus
}  // namespace pyrolume::display
#endif
#undef VIEW_FN
#endif
