#pragma once
// Scene::shapes -> Surfaces: meshes loaded and transformed, analytic shapes,
// one Lambertian material per shape, each albedo texture loaded once.
#include "geometry/Surfaces.h"
#include "scene/Scene.h"

namespace pyrolume::geometry {

// Throws InputError naming the file (a bad OBJ or texture) and the shape.
Surfaces build_surfaces(const Scene& scene);

}  // namespace pyrolume::geometry
