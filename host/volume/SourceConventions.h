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
// Blender's Principled Volume default Color (also Quick Smoke's): albedo 0.5.
inline constexpr double kDefaultSmokeAlbedo = 0.5;
// Blender's Quick Smoke material sets the Principled Volume's Density to 5.
inline constexpr double kBlenderSmokeDensity = 5.0;

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
  // Whether the file glows by its tool's own rule (docs/sources.md "Smoke is
  // smoke"): Blender's, Houdini's and EmberGen's fire shading is driven by a
  // flame grid, so none, or one zero everywhere, is smoke. Settled by
  // settle_emission; a guessed source and kelvin files glow from temperature.
  bool emits = true;
  std::string flame_grid;     // the grid that decides it ("": none with voxels)
  std::string emission_text;  // why, for `info` and notes
  // σs / (σa + σs) of the tool's default volume material, for media that do
  // not emit (Blender's Principled Volume: Color 0.5).
  double smoke_albedo = kDefaultSmokeAlbedo;
  // The density_scale such media get: the material's Density (Blender's
  // Quick Smoke material: 5; 1 elsewhere).
  double smoke_density_scale = 1.0;
  // Added to voxel indices before the grid's index->world map: where the tool
  // puts voxel ijk's value (0: at ijk, OpenVDB's cell-centred rule; 0.5:
  // Mantaflow's cell ijk spans [ijk, ijk+1], as Cycles reads it).
  double index_offset = 0.0;
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

// Whether the file emits (c.emits, c.emission_text): reads the flame grid's
// values when the metadata leaves open whether it is zero everywhere.
void settle_emission(SourceConvention& c, const std::string& file);

// A scene that renders the file with its defaults (for `pyrolume info`).
std::string scene_snippet(const std::string& file, const SourceConvention& c);

}  // namespace pyrolume
