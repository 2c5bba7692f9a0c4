#pragma once
// What the volume loaders take: a grid file, the grids to read, where they
// sit and how they are stored. The scene model (scene/Scene.h) names these
// types; scene/MediumVolume.h makes a VolumeOptions from a Medium.
#include <filesystem>
#include <string>

#include <glm/glm.hpp>

namespace pyrolume {

struct TemperatureMapping {
  double scale = 1.0;   // T = (value - offset) * scale, kelvin
  double offset = 0.0;
  double cutoff_k = 100.0;  // no emission at or below

  // A stored temperature value in kelvin: the one C++ copy of the mapping
  // (the GPU's is media.glsl temperature_kelvin).
  double kelvin(double value) const { return (value - offset) * scale; }
  // Of a grid whose values span [min_value, max_value], the value that maps
  // hottest (the smallest one under a negative scale), and its kelvin.
  double hottest_value(double min_value, double max_value) const { return scale >= 0.0 ? max_value : min_value; }
  double hottest_kelvin(double min_value, double max_value) const {
    return kelvin(hottest_value(min_value, max_value));
  }
};

// The simulator that wrote a vdb file (docs/sources.md): it decides the grids
// read, the temperature mapping and the up axis. Auto: detected from the file.
enum class VolumeSource { Auto, Blender, Houdini, EmberGen, Kelvin };

// Which world axis is up (a file's convention, or the scene's).
enum class UpAxis { Y, Z };

// The texture format grids are stored in (volume/StoredVolume.h): a dense 3D
// texture of halfs or floats, or a sparse NanoVDB tree of floats
// (volume/SparseGrid.h); Auto picks R16F or Sparse per grid (VdbLoader.h).
enum class TextureFormat { Auto, R16F, R32F, Sparse };
// Its name in the scene file (media[].texture_format).
inline const char* to_string(TextureFormat f) {
  switch (f) {
    case TextureFormat::R16F: return "r16f";
    case TextureFormat::R32F: return "r32f";
    case TextureFormat::Sparse: return "sparse";
    default: return "auto";
  }
}

struct VolumeOptions {
  std::filesystem::path file;
  std::string density_grid;      // empty: default "density"
  std::string temperature_grid;  // empty: first of temperature, heat, flame
  bool need_temperature = false; // read the temperature grid too
  glm::dmat4 transform{1.0};     // composed on top of each grid's index->world map
  double index_offset = 0.0;     // added to every voxel index first (a tool's voxel placement)
  int downsample = 1;
  TextureFormat texture_format = TextureFormat::Auto;  // R32F is also used when values exceed R16F
  TemperatureMapping temperature;  // for the warning when nothing glows
};

}  // namespace pyrolume
