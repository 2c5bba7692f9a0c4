#pragma once
// A vdb Medium of the scene model as the volume loaders take it
// (volume/VolumeOptions.h), and what a grid file's source convention sets on it.
#include <glm/glm.hpp>

#include "scene/Scene.h"
#include "volume/SourceConventions.h"
#include "volume/StoredVolume.h"
#include "volume/VdbLoader.h"

namespace pyrolume {

// The medium's `transform` as a matrix: T * Rz * Ry * Rx * S, i.e. scale first,
// then rotate about X, Y, Z (degrees, right-handed), then translate.
glm::dmat4 medium_transform_matrix(const Transform& t);

// A homogeneous medium's emitted radiance Le: emission.scale times its rgb or
// the blackbody colour of its temperature_k (0 without either).
glm::dvec3 homogeneous_le(const Emission& e);

// Whether a medium's emission needs its temperature grid.
bool needs_temperature_grid(const Medium& m);

// The loaders' options for a vdb medium: its file, grids, transform,
// downsample, texture_format and temperature mapping.
VolumeOptions volume_options(const Medium& m, bool need_temperature);

// load_volume / load_stored_volume (volume/) for a medium; the stored one
// reads the temperature grid when needs_temperature_grid(m).
VolumeGrids load_volume(const Medium& m, bool need_temperature, const DenseLimits& limits = {});
StoredVolume load_stored_volume(const Medium& m, const DenseLimits& limits = {});

// Sets what the scene file left unset on a vdb medium: the grids, the
// temperature mapping (each of scale, offset, cutoff_k only when not written),
// the voxel placement, and no emission where the convention finds no
// temperature grid, or finds the file is smoke (c.emits) and the scene asks
// for none; a medium left not emitting, with no sigma keys, scatters with the
// convention's albedo.
void apply_source_convention(Medium& m, const SourceConvention& c);

}  // namespace pyrolume
