#pragma once
// What a simulator's VDB export means (docs/sources.md): which grids hold
// density and temperature, how a temperature value maps to kelvin, and which
// axis is up. A vdb medium's `source` picks the convention ("auto", the
// default, detects it from the file's metadata and grid names); keys the scene
// file writes always win over it.
#include <optional>
#include <string>

#include "volume/VdbInfo.h"
#include "volume/VolumeOptions.h"

namespace pyrolume {

// "auto" | "blender" | "houdini" | "embergen" | "kelvin".
const char* to_string(VolumeSource source);

// Where a fitted mapping puts the hottest voxel (houdini, embergen: their
// temperatures have no documented unit).
inline constexpr double kFittedHottestK = 2500.0;
// A guessed source whose temperatures exceed this reads them as kelvin.
inline constexpr double kKelvinLookingAbove = 200.0;

struct SourceConvention {
  VolumeSource source = VolumeSource::Kelvin;  // never Auto
  std::string why;       // what decided it: "creator \"Blender/Smoke\"", "grid names ...", ...
  bool guessed = false;  // auto found nothing to go by and fell back to the default
  std::string density_grid = "density";
  std::string temperature_grid;  // empty: no grid to glow from (smoke only)
  TemperatureMapping mapping;
  // The mapping is fitted to the temperature grid's largest value:
  // T = value · kFittedHottestK / max (resolved by fit_temperature_mapping).
  bool fit_to_range = false;
  std::string mapping_text;  // the mapping in words, for `info` and notes
  UpAxis up_axis = UpAxis::Y;
};

// The convention for a file, from `requested` (Auto: detected from metadata and
// grid names) and the temperature grid the scene names, if any (empty: the
// convention chooses). Reads nothing but `info`.
SourceConvention source_convention(const VolumeFileInfo& info, VolumeSource requested,
                                   const std::string& temperature_grid = "");

// A fitted mapping's scale from the temperature grid's largest active value
// (read from the file); leaves the convention unchanged when it is not fitted.
// A grid whose values are all <= 0 keeps scale 1 (nothing glows; the loader's
// warning says so).
void fit_temperature_mapping(SourceConvention& c, const std::string& file);

// A scene that renders the file with its defaults (for `pyrolume info`).
std::string scene_snippet(const std::string& file, const SourceConvention& c);

}  // namespace pyrolume
