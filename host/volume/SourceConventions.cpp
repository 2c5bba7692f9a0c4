#include "volume/SourceConventions.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "util/Error.h"

namespace pyrolume {

const char* to_string(VolumeSource source) {
  switch (source) {
    case VolumeSource::Auto: return "auto";
    case VolumeSource::Blender: return "blender";
    case VolumeSource::Houdini: return "houdini";
    case VolumeSource::EmberGen: return "embergen";
    case VolumeSource::Kelvin: return "kelvin";
  }
  return "?";
}

namespace {

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }
bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

// A grid that exists and may hold voxels (an unknown count counts as non-empty).
bool has_voxels(const VolumeFileInfo& info, const std::string& name) {
  const GridInfo* g = info.grid(name);
  return g && !g->empty();
}

std::string first_present(const VolumeFileInfo& info, std::initializer_list<const char*> names) {
  for (const char* n : names)
    if (has_voxels(info, n)) return n;
  return "";
}

// Auto: the simulator, from the file's metadata first (what the writer says
// about itself), then from grid names each simulator alone uses.
VolumeSource detect(const VolumeFileInfo& info, std::string& why, bool& guessed) {
  guessed = false;
  for (const auto& [key, value] : info.metadata)
    if (starts_with(key, "embergen")) {
      why = "metadata \"" + key + "\"";
      return VolumeSource::EmberGen;
    }
  const std::string creator = info.metadata_value("creator");
  if (starts_with(creator, "Blender")) {
    why = "creator \"" + creator + "\"";
    return VolumeSource::Blender;
  }
  if (contains(creator, "Houdini")) {
    why = "creator \"" + creator + "\"";
    return VolumeSource::Houdini;
  }
  if (contains(creator, "EmberGen") || contains(creator, "JangaFX")) {
    why = "creator \"" + creator + "\"";
    return VolumeSource::EmberGen;
  }
  for (const auto& [key, value] : info.metadata)
    if (starts_with(key, "blender/")) {
      why = "metadata \"" + key + "\"";
      return VolumeSource::Blender;
    }
  // Blender 2.7x smoke writes "heat"; Mantaflow (Blender 2.8+) writes "shadow"
  // and "color_r/g/b"; both write "fuel" and "react" beside "flame".
  for (const char* name : {"heat", "shadow", "fuel", "react", "color_r"})
    if (info.grid(name)) {
      why = std::string("grid \"") + name + "\" (Blender's smoke and Mantaflow caches)";
      return VolumeSource::Blender;
    }
  if (info.grid("vel")) {  // Houdini names velocity "vel"
    why = "grid \"vel\" (Houdini's velocity)";
    return VolumeSource::Houdini;
  }
  guessed = true;
  why = "nothing in the file names its simulator";
  return VolumeSource::Houdini;
}

// A Blender fluid cache written by Mantaflow (Blender 2.82+), not by 2.7x's
// smoke point cache: 2.7x writes creator "Blender/Smoke" and a "heat" grid.
bool is_mantaflow(const VolumeFileInfo& info) {
  return !starts_with(info.metadata_value("creator"), "Blender/Smoke") && !info.grid("heat");
}

// The tool's fire shading reads a flame grid (Blender's Quick Smoke material
// turns on Blackbody Intensity only for its Fire styles; Houdini's Pyro
// shader takes fire intensity from "flame", "heat" before 17.5). Without one
// that holds voxels the file is smoke; one whose values are known to be all
// zero is smoke too (settle_emission reads them when the metadata does not).
void decide_emission(SourceConvention& c, const VolumeFileInfo& info, std::initializer_list<const char*> flames) {
  c.flame_grid = first_present(info, flames);
  if (c.flame_grid.empty()) {
    c.emits = false;
    c.emission_text = "no flame grid with voxels: smoke, no emission";
    return;
  }
  const GridInfo* g = info.grid(c.flame_grid);
  if (g->min_value && g->max_value && *g->min_value == 0.0 && *g->max_value == 0.0) {
    c.emits = false;
    c.emission_text = "grid \"" + c.flame_grid + "\" is zero everywhere: smoke, no emission";
    return;
  }
  c.emission_text = "emits: grid \"" + c.flame_grid + "\" holds flame";
}

}  // namespace

SourceConvention source_convention(const VolumeFileInfo& info, VolumeSource requested,
                                   const std::string& temperature_grid) {
  SourceConvention c;
  if (requested == VolumeSource::Auto) {
    c.source = detect(info, c.why, c.guessed);
  } else {
    c.source = requested;
    c.why = "the scene's \"source\"";
  }
  switch (c.source) {
    case VolumeSource::Blender: {
      // What Cycles shows for the file: a Volume object's grids are attributes
      // of the same name, and the Principled Volume multiplies its temperature
      // attribute by its Temperature socket, 1000 K by default. The attribute
      // is "temperature" (Mantaflow's name for heat) or, in 2.7x caches, "heat".
      c.up_axis = UpAxis::Z;
      c.temperature_grid = temperature_grid.empty() ? first_present(info, {"temperature", "heat"}) : temperature_grid;
      if (c.temperature_grid == "flame") {
        // A fluid domain's own "temperature" attribute is made from flame:
        // ignition + flame·(maximum − ignition) where flame > 0.01, in units of
        // 1000 K, defaults ignition 1.5 and maximum 3.0: T = 1500·(flame + 1) K,
        // nothing at or below flame 0.01 (1515 K).
        c.mapping = {1500.0, -1.0, 1515.0};
        c.mapping_text = "T = 1500·(flame + 1) K where flame > 0.01 (a Blender fluid domain's fire temperature)";
      } else if (!c.temperature_grid.empty()) {
        c.mapping = {1000.0, 0.0, 100.0};
        c.mapping_text = "T = 1000·" + c.temperature_grid + " K (Cycles' Principled Volume Temperature, 1000 K)";
      } else {
        c.mapping_text = "no temperature or heat grid with voxels: smoke only, no emission";
      }
      decide_emission(c, info, {"flame"});
      // Cycles reads a VDB's voxel ijk as the cell [ijk, ijk+1] (its value at
      // ijk + 0.5), and Mantaflow writes the cell's corner as ijk: the cache
      // sits half a voxel higher on every axis than OpenVDB's cell-centred rule
      // puts it. 2.7x caches add that half voxel to their transform already.
      if (is_mantaflow(info)) c.index_offset = 0.5;
      // Quick Smoke's material: a Principled Volume of Density 5, Color 0.5
      // (σs = Color·Density, σa = (1 − Color)·Density per unit of the grid).
      c.smoke_density_scale = kBlenderSmokeDensity;
      break;
    }
    case VolumeSource::Houdini:
    case VolumeSource::EmberGen: {
      // Pyro's and EmberGen's temperatures have no unit (Pyro: ambient 0,
      // burning ~1): fit the range, as Karma's Pyro shader does.
      c.up_axis = UpAxis::Y;
      c.temperature_grid = temperature_grid.empty() ? first_present(info, {"temperature", "flame", "flames", "heat"})
                                                    : temperature_grid;
      c.mapping = {1.0, 0.0, 100.0};
      c.fit_to_range = !c.temperature_grid.empty();
      c.mapping_text = c.temperature_grid.empty()
                           ? "no temperature grid with voxels: smoke only, no emission"
                           : "T = " + c.temperature_grid + " · " + std::to_string(int(kFittedHottestK)) +
                                 " K / its largest value (fitted: the file's temperature has no unit)";
      // A guess keeps glowing from its temperature (what it did before).
      if (!c.guessed) decide_emission(c, info, {"flame", "flames", "heat"});
      break;
    }
    case VolumeSource::Kelvin:
    case VolumeSource::Auto: {
      c.source = VolumeSource::Kelvin;
      c.up_axis = UpAxis::Y;
      c.temperature_grid =
          temperature_grid.empty() ? first_present(info, {"temperature", "heat", "flame"}) : temperature_grid;
      c.mapping = {1.0, 0.0, 100.0};
      c.mapping_text = c.temperature_grid.empty() ? "no temperature grid with voxels: smoke only, no emission"
                                                  : "T = " + c.temperature_grid + " K";
      break;
    }
  }
  return c;
}

void settle_emission(SourceConvention& c, const std::string& file) {
  if (!c.emits || c.flame_grid.empty()) return;
  const VolumeFileInfo info = read_volume_file_info(file, true, c.flame_grid);
  const GridInfo* g = info.grid(c.flame_grid);
  if (g && g->min_value && g->max_value && *g->min_value == 0.0 && *g->max_value == 0.0) {
    c.emits = false;
    c.emission_text = "grid \"" + c.flame_grid + "\" is zero everywhere: smoke, no emission";
  }
}

void fit_temperature_mapping(SourceConvention& c, const std::string& file) {
  if (!c.fit_to_range || c.temperature_grid.empty()) return;
  const VolumeFileInfo info = read_volume_file_info(file, true, c.temperature_grid);
  const GridInfo* g = info.grid(c.temperature_grid);
  if (!g || !g->max_value || !(*g->max_value > 0.0)) return;
  const double hottest = *g->max_value;
  // A guess (nothing named the simulator) whose values already look like
  // kelvin keeps them: no simulator writes unitless temperatures in the hundreds.
  if (c.guessed && hottest > kKelvinLookingAbove) {
    c.source = VolumeSource::Kelvin;
    c.fit_to_range = false;
    c.mapping = {1.0, 0.0, 100.0};
    std::ostringstream s;  // not int(hottest): a forged 1e30 overflowed to -2147483648
    s << "T = " << c.temperature_grid << " K (its largest value, " << hottest << ", reads as kelvin)";
    c.mapping_text = s.str();
    return;
  }
  c.mapping.scale = kFittedHottestK / hottest;
  std::ostringstream s;
  s << "T = " << c.temperature_grid << " · " << c.mapping.scale << " K (fitted: its largest value, " << hottest
    << ", at " << kFittedHottestK << " K)";
  c.mapping_text = s.str();
}

std::string scene_snippet(const std::string& file, const SourceConvention& c) {
  std::ostringstream s;
  s << "{\"media\": [{\"type\": \"vdb\", \"file\": \"" << file << "\"}]}\n"
    << "  source " << to_string(c.source) << " (" << c.why << (c.guessed ? "; a guess" : "") << "), up axis "
    << (c.up_axis == UpAxis::Z ? "z" : "y") << "\n"
    << "  density from grid \"" << c.density_grid << "\"; "
    << (c.temperature_grid.empty() ? "" : "temperature from grid \"" + c.temperature_grid + "\": ") << c.mapping_text
    << "\n";
  if (!c.temperature_grid.empty() && !c.emits)
    s << "  " << c.emission_text << " (write an \"emission\" block to make it glow)\n";
  if (c.temperature_grid.empty() || !c.emits)
    s << "  smoke scatters: albedo " << c.smoke_albedo << " (sigma_s " << c.smoke_albedo << ", sigma_a "
      << 1.0 - c.smoke_albedo << "), density_scale " << c.smoke_density_scale << "\n";
  if (c.index_offset != 0.0) s << "  voxel ijk placed at ijk + " << c.index_offset << " (Mantaflow's cell corner)\n";
  return s.str();
}

}  // namespace pyrolume
