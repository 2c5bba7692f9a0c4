#pragma once
// The scene as parsed and validated from scene JSON (format v1, docs/scene-format.md).
// Units: lengths in scene units, sigma in 1/scene-unit, temperatures in kelvin,
// radiance linear sRGB.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace pyrolume {

struct Camera {
  glm::dvec3 position{0, 1, -6};
  glm::dvec3 look_at{0, 1, 0};
  glm::dvec3 up{0, 1, 0};
  double fov_deg = 40.0;  // vertical field of view
};

struct Film {
  int width = 640;
  int height = 360;
  int spp = 64;
  double exposure = 0.0;  // stops, applied to PNG output only
  uint32_t seed = 1;
};

struct Integrator {
  int max_depth = 8;
  bool mis = true;  // accepted; used once MIS lands
  std::string emission_estimator = "absorption";  // "absorption" | "collision"
  std::string majorant = "grid";                  // "grid" | "global"
  std::optional<glm::ivec3> majorant_grid;
};

struct Environment {
  std::filesystem::path file;  // resolved against the scene folder
  double scale = 1.0;
  double rotation_deg = 0.0;
};

struct Bounds {
  enum class Kind { Sphere, Box };
  Kind kind = Kind::Sphere;
  glm::dvec3 center{0.0};
  double radius = 1.0;
  glm::dvec3 min{0.0}, max{0.0};
};

enum class BlackbodyMode { Seed, Peak, Physical };

struct Emission {
  // Exactly one of rgb / temperature_k is set for homogeneous media; grid media
  // take their temperature from the grid (then neither is set).
  std::optional<glm::dvec3> rgb;
  std::optional<double> temperature_k;
  double scale = 1.0;
  BlackbodyMode blackbody = BlackbodyMode::Seed;
  int observer = 2;  // CIE 1931 2° or CIE 1964 10°
  std::optional<double> adapt_to_k;
  bool emits() const { return (rgb || temperature_k || is_grid) && scale > 0.0; }
  bool is_grid = false;  // temperature comes from a grid
};

struct TemperatureMapping {
  double scale = 1.0;   // T = (value - offset) * scale, kelvin
  double offset = 0.0;
  double cutoff_k = 100.0;  // no emission at or below
};

struct Transform {
  glm::dvec3 translate{0.0};
  glm::dvec3 rotate_deg{0.0};  // X, then Y, then Z, right-handed
  glm::dvec3 scale{1.0};
};

struct Medium {
  enum class Type { Homogeneous, Vdb };
  std::string name;
  Type type = Type::Homogeneous;
  Bounds bounds;  // homogeneous only
  glm::dvec3 sigma_a{1.0}, sigma_s{0.0};
  double g = 0.0;  // Henyey–Greenstein, g > 0 scatters forward
  Emission emission;
  // vdb only
  std::filesystem::path file;
  std::string density_grid;      // empty: default "density"
  std::string temperature_grid;  // empty: first of temperature, heat, flame
  double density_scale = 1.0;
  TemperatureMapping temperature;
  Transform transform;
  int downsample = 1;
  std::string texture_format = "r16f";  // "r16f" | "r32f" (R32F is also used when values exceed R16F)
};

// A surface: a triangle mesh (OBJ), an analytic sphere, or a plane (a
// rectangle, or unbounded along an axis whose size is 0), with a Lambertian
// material whose albedo is a constant or a texture.
struct Shape {
  enum class Type { Mesh, Sphere, Plane };
  Type type = Type::Mesh;
  std::filesystem::path mesh;  // mesh
  Transform transform;         // mesh: scale, rotate (X, Y, Z), translate
  glm::dvec3 center{0.0};      // sphere, plane
  double radius = 1.0;         // sphere
  glm::dvec3 normal{0, 1, 0};  // plane
  glm::dvec2 size{0.0};        // plane: extent along its u and v axes; 0 = unbounded
  glm::dvec3 albedo{0.5};
  std::filesystem::path texture;  // empty: constant albedo
};

struct Scene {
  std::filesystem::path file;  // the JSON it came from (for messages)
  Camera camera;
  Film film;
  Integrator integrator;
  glm::dvec3 background{0.0};  // constant radiance seen by escaping rays
  std::optional<Environment> environment;
  std::vector<Medium> media;
  std::vector<Shape> shapes;
};

// Parse and validate. Throws InputError("FILE: key.path: reason").
Scene load_scene(const std::filesystem::path& file);
Scene parse_scene(const std::string& json_text, const std::filesystem::path& file);

}  // namespace pyrolume
