// Scene JSON (format v1) -> Scene, with strict validation: unknown keys, wrong
// types and out-of-range values are errors that name the file and key path, so a
// typo never silently renders something else.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "color/EmissionModel.h"
#include "scene/Scene.h"
#include "scene/SceneReader.h"
#include "util/Error.h"
#include "util/InputFile.h"
#include "util/Json.h"
#include "util/Suggest.h"

namespace pyrolume {
namespace {

using json = nlohmann::json;
using scene_file::Reader;

std::optional<glm::dvec3> scaled_direction(const glm::dvec3& d) {
  const double largest = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
  if (!(largest > 0)) return std::nullopt;
  return d / largest;
}

// Every coordinate of p within ±kMaxCoordinate, else an error naming `key`.
void check_coordinate(Reader& r, const std::string& key, const glm::dvec3& p, const std::string& what) {
  for (int i = 0; i < 3; ++i)
    if (!(std::abs(p[i]) <= kMaxCoordinate))
      r.fail(key, what + " reaches " + json(p[i]).dump() + ", beyond the ±" + json(kMaxCoordinate).dump() +
                      " that float ray arithmetic keeps finite");
}

std::filesystem::path resolve(const std::filesystem::path& base, const std::string& p) {
  std::filesystem::path path(p);
  return path.is_absolute() ? path : (base / path).lexically_normal();
}

Bounds read_bounds(Reader r) {
  Bounds b;
  bool sphere = r.has("sphere"), box = r.has("box");
  if (sphere == box) r.fail("", "expected exactly one of \"sphere\" or \"box\"");
  if (sphere) {
    Reader s = r.child("sphere");
    b.kind = Bounds::Kind::Sphere;
    b.center = s.vec3_required("center");
    b.radius = s.number_required("radius");
    if (!(b.radius > 0)) s.fail("radius", "must be > 0");
    s.finish();
  } else {
    Reader s = r.child("box");
    b.kind = Bounds::Kind::Box;
    b.min = s.vec3_required("min");
    b.max = s.vec3_required("max");
    if (!(b.min.x < b.max.x && b.min.y < b.max.y && b.min.z < b.max.z)) s.fail("max", "must exceed min on every axis");
    s.finish();
  }
  r.finish();
  return b;
}

BlackbodyMode read_blackbody(Reader& r) {
  // "seed" is the old name of "chromaticity", still read.
  const std::string m = r.choice("blackbody", "stefan_boltzmann",
                                 {"stefan_boltzmann", "physical", "peak", "chromaticity", "seed"});
  return m == "peak"               ? BlackbodyMode::Peak
         : m == "physical"         ? BlackbodyMode::Physical
         : m == "stefan_boltzmann" ? BlackbodyMode::StefanBoltzmann
                                   : BlackbodyMode::Seed;
}

VolumeSource read_source(Reader& r) {
  const std::string s = r.choice("source", "auto", {"auto", "blender", "houdini", "embergen", "kelvin"});
  return s == "blender"    ? VolumeSource::Blender
         : s == "houdini"  ? VolumeSource::Houdini
         : s == "embergen" ? VolumeSource::EmberGen
         : s == "kelvin"   ? VolumeSource::Kelvin
                           : VolumeSource::Auto;
}

Emission read_emission(Reader r, bool grid) {
  Emission e;
  e.is_grid = grid;
  if (r.has("rgb")) e.rgb = r.nonnegative_rgb("rgb", {});
  if (r.has("temperature_k")) {
    if (grid) r.fail("temperature_k", "a vdb medium takes its temperature from its grid (see \"temperature\")");
    double t = r.number("temperature_k", 0);
    if (t < 0) r.fail("temperature_k", "must be >= 0 kelvin");
    e.temperature_k = t;
  }
  if (e.rgb && e.temperature_k) r.fail("rgb", "give either rgb or temperature_k, not both");
  e.scale = r.number_keyed("scale", 1.0, e.scale_keys);
  if (e.scale < 0) r.fail("scale", "must be >= 0");
  for (size_t n = 0; n < e.scale_keys.values.size(); ++n)
    if (e.scale_keys.values[n] < 0) r.fail("scale.keys[" + std::to_string(n) + "]", "must be >= 0");
  e.blackbody = read_blackbody(r);
  e.observer = r.integer("observer", 2, 2, 10);
  if (e.observer != 2 && e.observer != 10) r.fail("observer", "must be 2 (CIE 1931) or 10 (CIE 1964)");
  if (r.has("adapt_to_k")) {
    double a = r.number("adapt_to_k", 0);
    if (!(a > 0)) r.fail("adapt_to_k", "must be > 0 kelvin");
    e.adapt_to_k = a;
  }
  if (grid && e.rgb) e.is_grid = false;  // constant colour times density
  r.finish();
  return e;
}

Transform read_transform(Reader t);

Medium read_medium(Reader r, const std::filesystem::path& base, int index) {
  Medium m;
  m.name = r.string("name", "medium" + std::to_string(index));
  std::string type = r.choice("type", "", {"homogeneous", "vdb"});
  m.type = type == "vdb" ? Medium::Type::Vdb : Medium::Type::Homogeneous;
  m.given.sigma = r.has("sigma_a") || r.has("sigma_s");
  m.sigma_a = r.nonnegative_rgb("sigma_a", m.sigma_a);
  m.sigma_s = r.nonnegative_rgb("sigma_s", m.sigma_s);
  m.g = r.number("g", 0.0);
  if (!(std::abs(m.g) < 1.0)) r.fail("g", "must satisfy |g| < 1");
  if (m.type == Medium::Type::Homogeneous) {
    if (!r.has("bounds")) r.fail("bounds", "missing required key (a homogeneous medium needs a sphere or box)");
    m.bounds = read_bounds(r.child("bounds"));
  } else {
    if (r.has("bounds")) r.fail("bounds", "a vdb medium is bounded by its grids");
    if (!r.has("file")) r.fail("file", "missing required key");
    m.file = resolve(base, r.string("file", ""));
    m.source = read_source(r);
    m.density_grid = r.string("density_grid", "");
    m.temperature_grid = r.string("temperature_grid", "");
    m.given.temperature_grid = !m.temperature_grid.empty();
    m.given.density_scale = r.has("density_scale");
    m.density_scale = r.number("density_scale", 1.0);
    if (m.density_scale < 0) r.fail("density_scale", "must be >= 0");
    m.downsample = r.integer("downsample", 1, 1, 64);
    m.texture_format = r.enum_choice("texture_format", TextureFormat::Auto,
                                      {TextureFormat::Auto, TextureFormat::R16F, TextureFormat::R32F, TextureFormat::Sparse});
    if (m.texture_format == TextureFormat::Sparse && m.downsample > 1)
      r.fail("downsample", "a sparse grid keeps every voxel; downsampling needs a dense texture_format (r16f or r32f)");
    if (r.has("temperature")) {
      Reader t = r.child("temperature");
      m.given.temperature_scale = t.has("scale");
      m.given.temperature_offset = t.has("offset");
      m.given.temperature_cutoff = t.has("cutoff_k");
      m.temperature.scale = t.number("scale", 1.0);
      m.temperature.offset = t.number("offset", 0.0);
      m.temperature.cutoff_k = t.number("cutoff_k", 100.0);
      if (m.temperature.cutoff_k < 0) t.fail("cutoff_k", "must be >= 0 kelvin");
      t.finish();
    }
    if (r.has("transform")) m.transform = read_transform(r.child("transform"));
  }
  m.given.emission = r.has("emission");
  if (r.has("emission")) m.emission = read_emission(r.child("emission"), m.type == Medium::Type::Vdb);
  // A vdb medium without an emission block glows where its source convention
  // finds a temperature (host/volume/SourceConventions); a homogeneous one does not.
  else m.emission.is_grid = m.type == Medium::Type::Vdb;
  r.finish();
  return m;
}

Transform read_transform(Reader t) {
  Transform x;
  x.translate = t.vec3("translate", x.translate);
  x.rotate_deg = t.vec3("rotate_deg", x.rotate_deg);
  x.scale = t.vec3("scale", x.scale);
  if (x.scale.x == 0 || x.scale.y == 0 || x.scale.z == 0) t.fail("scale", "must be non-zero on every axis");
  t.finish();
  return x;
}

Shape read_shape(Reader r, const std::filesystem::path& base) {
  Shape s;
  int kinds = int(r.has("mesh")) + int(r.has("sphere")) + int(r.has("plane"));
  if (kinds != 1) r.fail("", "expected exactly one of \"mesh\", \"sphere\" or \"plane\"");
  if (r.has("mesh")) {
    s.type = Shape::Type::Mesh;
    s.mesh = resolve(base, r.string("mesh", ""));
    if (r.has("transform")) s.transform = read_transform(r.child("transform"));
  } else if (r.has("sphere")) {
    s.type = Shape::Type::Sphere;
    Reader sp = r.child("sphere");
    s.center = sp.vec3_required("center");
    s.radius = sp.number_required("radius");
    if (!(s.radius > 0)) sp.fail("radius", "must be > 0");
    sp.finish();
  } else {
    s.type = Shape::Type::Plane;
    Reader pl = r.child("plane");
    s.center = pl.vec3("center", s.center);
    s.normal = pl.vec3("normal", s.normal);
    const std::optional<glm::dvec3> n = scaled_direction(s.normal);
    if (!n) pl.fail("normal", "must not be zero");
    s.normal = *n;
    if (pl.has("size")) {
      const auto& v = pl.raw("size");
      if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number() || v[0].get<double>() < 0 ||
          v[1].get<double>() < 0)
        pl.fail("size", "expected [width, height] >= 0 (0 = unbounded)");
      s.size = glm::dvec2(v[0].get<double>(), v[1].get<double>());
    }
    pl.finish();
  }
  if (r.has("material")) {
    Reader m = r.child("material");
    if (m.has("diffuse")) {
      Reader d = m.child("diffuse");
      s.albedo = d.nonnegative_rgb("rgb", s.albedo);
      if (s.albedo.x > 1 || s.albedo.y > 1 || s.albedo.z > 1) d.fail("rgb", "albedo must be <= 1 in every channel");
      if (d.has("texture")) s.texture = resolve(base, d.string("texture", ""));
      d.finish();
    }
    m.finish();
  }
  r.finish();
  return s;
}

}  // namespace

std::optional<IntegratorConflict> integrator_conflict(const Integrator& in, bool has_lights) {
  if (in.allows_light_sampling()) return std::nullopt;
  const bool mis_off = in.mis == false;  // otherwise the absorption estimator turned it off
  if (has_lights && mis_off)
    return IntegratorConflict{"mis", "false turns off light sampling, the only way the scene's \"lights\" are reached "
                                     "(remove it, or remove the lights)"};
  if (has_lights)
    return IntegratorConflict{"emission_estimator", "\"absorption\" turns off light sampling, the only way the scene's "
                                                    "\"lights\" are reached (write \"auto\" or leave it out)"};
  if (in.light_only && mis_off)
    return IntegratorConflict{"light_only", "true asks for light sampling, which \"mis\": false turns off"};
  if (in.light_only)
    return IntegratorConflict{"light_only", "true asks for light sampling, which needs the collision estimator, "
                                            "not \"emission_estimator\": \"absorption\" (write \"auto\" or leave it out)"};
  if (in.mis == true)
    return IntegratorConflict{"emission_estimator", "\"absorption\" contradicts \"mis\": true (light sampling needs "
                                                    "the collision estimator: write \"auto\" or leave it out)"};
  return std::nullopt;
}

Light read_light(Reader r) {
  Light l;
  if (!r.has("type")) r.fail("type", "missing required key (\"distant\", \"point\", \"spot\" or \"sphere\")");
  const std::string type = r.choice("type", "", {"distant", "point", "spot", "sphere"});
  l.type = type == "distant" ? Light::Type::Distant
           : type == "point" ? Light::Type::Point
           : type == "spot"  ? Light::Type::Spot
                             : Light::Type::Sphere;
  // The colour key names the quantity: what a plane facing a distant light
  // receives, what a point or spot radiates per steradian, a sphere's radiance.
  const char* value_key = l.type == Light::Type::Distant ? "irradiance"
                          : l.type == Light::Type::Sphere ? "radiance"
                                                          : "intensity";
  if (r.has(value_key)) l.rgb = r.nonnegative_rgb(value_key, {});
  if (r.has("temperature_k")) {
    // The blackbody range the renderers evaluate (color/EmissionModel.h):
    // below it Planck's law underflows to black, above it overflows.
    const double t = r.number("temperature_k", 0.0);
    if (!(t >= kEmissionMinK && t <= kEmissionMaxK))
      r.fail("temperature_k", "must be in [" + json(kEmissionMinK).dump() + ", " + json(kEmissionMaxK).dump() +
                                  "] kelvin, got " + json(t).dump());
    l.temperature_k = t;
  }
  if (l.rgb && l.temperature_k) r.fail(value_key, std::string("give either ") + value_key + " or temperature_k, not both");
  if (!l.rgb && !l.temperature_k) r.fail(value_key, std::string("missing: give ") + value_key + " (rgb) or temperature_k");
  l.scale = r.number("scale", 1.0);
  if (l.scale < 0) r.fail("scale", "must be >= 0");
  auto unit_direction = [&](const char* key) {
    const std::optional<glm::dvec3> d = scaled_direction(r.vec3_required(key));
    if (!d) r.fail(key, "must not be zero");
    return glm::normalize(*d);
  };
  auto position = [&](const char* key) {
    const glm::dvec3 p = r.vec3_required(key);
    check_coordinate(r, key, p, "a coordinate");
    return p;
  };
  switch (l.type) {
    case Light::Type::Distant:
      l.direction = unit_direction("direction");
      l.angle_deg = r.number("angle_deg", 0.0);
      if (!(l.angle_deg >= 0 && l.angle_deg < 180)) r.fail("angle_deg", "must be in [0, 180) degrees");
      if (l.angle_deg > 0 && l.angle_deg < kMinDiscAngleDeg)
        r.fail("angle_deg", "must be 0 (a delta light) or at least " + json(kMinDiscAngleDeg).dump() +
                                " degrees (a narrower disc is finer than float directions resolve), got " +
                                json(l.angle_deg).dump());
      break;
    case Light::Type::Point:
      l.position = position("position");
      break;
    case Light::Type::Spot:
      l.position = position("position");
      l.direction = unit_direction("direction");
      l.cone_deg = r.number("cone_deg", l.cone_deg);
      if (!(l.cone_deg > 0 && l.cone_deg <= 180)) r.fail("cone_deg", "must be in (0, 180] degrees");
      l.falloff_deg = r.number("falloff_deg", l.falloff_deg);
      if (!(l.falloff_deg >= 0)) r.fail("falloff_deg", "must be >= 0 degrees");
      if (l.cone_deg < l.falloff_deg)
        r.fail("cone_deg", "must be >= falloff_deg (the soft edge lies inside the cone), got cone_deg " +
                               json(l.cone_deg).dump() + " < falloff_deg " + json(l.falloff_deg).dump());
      break;
    case Light::Type::Sphere:
      l.center = position("center");
      l.radius = r.number("radius", 0.0);
      if (!r.has("radius")) r.fail("radius", "missing required key");
      if (!(l.radius > 0)) r.fail("radius", "must be > 0");
      // Its extent, as a sphere shape's: r² and |c ± r| stay within float.
      check_coordinate(r, "radius", glm::abs(l.center) + l.radius, "the sphere's extent |center| + radius");
      break;
  }
  r.finish();
  return l;
}

Scene parse_scene(const std::string& json_text, const std::filesystem::path& file) {
  const std::string fname = file.string();
  json root;
  try {
    root = parse_json_unique_keys(json_text, fname);  // a repeated key is an InputError
  } catch (const json::exception& e) {
    // parse_error, and out_of_range for a number beyond double (1e400: found
    // by fuzz_scene). nlohmann's message carries the byte offset; keep it on one line.
    std::string what = e.what();
    throw input_error(fname, "", "invalid JSON: " + what);
  }
  const std::filesystem::path base = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  Scene s;
  s.file = file;
  Reader r(root, "", fname);

  s.default_lights = r.boolean("default_lights", true);
  if (r.has("up_axis")) s.up_axis = r.choice("up_axis", "y", {"y", "z"}) == "z" ? UpAxis::Z : UpAxis::Y;
  s.camera.framed_automatically = true;
  if (r.has("camera")) {
    Reader c = r.child("camera");
    s.camera.framed_automatically = !c.has("position") && !c.has("look_at");
    s.camera.up_given = c.has("up");
    s.camera.position = c.vec3_keyed("position", s.camera.position, s.camera.position_keys);
    s.camera.look_at = c.vec3_keyed("look_at", s.camera.look_at, s.camera.look_at_keys);
    s.camera.up = c.vec3("up", s.camera.up);
    s.camera.fov_deg = c.number("fov_deg", s.camera.fov_deg);
    if (!(s.camera.fov_deg > 0 && s.camera.fov_deg < 180)) c.fail("fov_deg", "must be in (0, 180) degrees");
    glm::dvec3 f = s.camera.look_at - s.camera.position;
    if (glm::length(f) == 0) c.fail("look_at", "must differ from position");
    if (s.camera.up_given && glm::length(glm::cross(glm::normalize(f), s.camera.up)) < 1e-9)
      c.fail("up", "must not be parallel to the view direction");
    c.finish();
  }
  // Settled again once the up axis is known (render/SceneSetup), and per frame.
  if (!s.camera.up_given)
    s.camera.up = default_camera_up(s.up_axis.value_or(UpAxis::Y), s.camera.look_at - s.camera.position);
  if (r.has("film")) {
    Reader f = r.child("film");
    s.film.size_given = f.has("width") || f.has("height");
    s.film.width = f.integer("width", s.film.width, 1, kMaxFilmSide);
    s.film.height = f.integer("height", s.film.height, 1, kMaxFilmSide);
    s.film.spp = f.integer("spp", s.film.spp, kMinSpp, kMaxSpp);
    if (f.has("exposure") && f.raw("exposure").is_string()) {
      const std::string e = f.string("exposure", "");
      if (e != "auto") f.fail("exposure", "expected a number of stops, keys or \"auto\", got \"" + e + "\"");
      s.film.exposure_auto = true;
    } else {
      s.film.exposure = f.number_keyed("exposure", s.film.exposure, s.film.exposure_keys);
      const std::string limit = "must be within ±" + std::to_string(int(kMaxExposureStops)) + " stops";
      if (std::abs(s.film.exposure) > kMaxExposureStops && !s.film.exposure_keys.animated())
        f.fail("exposure", limit + ", got " + json(s.film.exposure).dump());
      for (size_t n = 0; n < s.film.exposure_keys.values.size(); ++n)
        if (std::abs(s.film.exposure_keys.values[n]) > kMaxExposureStops)
          f.fail("exposure.keys[" + std::to_string(n) + "]", limit + ", got " + json(s.film.exposure_keys.values[n]).dump());
    }
    s.film.view = *view_from_name(f.choice("view", to_string(kDefaultView), view_names(), /*suggest=*/true));
    s.film.seed = static_cast<uint32_t>(f.integer("seed", static_cast<int>(s.film.seed), 0, 2147483647));
    s.film.transparent = f.boolean("transparent", false);
    s.film.aovs = f.boolean("aovs", false);
    f.finish();
  }
  if (r.has("integrator")) {
    Reader i = r.child("integrator");
    s.integrator.max_depth = i.integer("max_depth", s.integrator.max_depth, 0, 100000);
    if (i.has("mis")) s.integrator.mis = i.boolean("mis", true);
    s.integrator.light_only = i.boolean("light_only", s.integrator.light_only);
    if (i.has("guided_continuation")) {
      const double g = i.number("guided_continuation", 0.0);
      if (!(g >= 0.0 && g < 1.0)) i.fail("guided_continuation", "expected a number in [0, 1)");
      s.integrator.guided_continuation = g;
    }
    s.integrator.surface_light_samples =
        i.integer("surface_light_samples", s.integrator.surface_light_samples, 1, 64);
    s.integrator.ratio_tracked_continuation =
        i.boolean("ratio_tracked_continuation", s.integrator.ratio_tracked_continuation);
    s.integrator.emission_estimator = i.optional_choice(
        "emission_estimator", "auto",
        {EmissionEstimator::Absorption, EmissionEstimator::Collision, EmissionEstimator::Line}, "auto");
    if (const std::optional<IntegratorConflict> c = integrator_conflict(s.integrator)) i.fail(c->key, c->reason);
    s.integrator.majorant = i.enum_choice("majorant", Majorant::Grid, {Majorant::Grid, Majorant::Global});
    if (i.has("majorant_grid")) {
      glm::dvec3 g = i.vec3("majorant_grid", {});
      for (int k = 0; k < 3; ++k)
        if (g[k] < 1 || g[k] > 1024 || g[k] != std::floor(g[k])) i.fail("majorant_grid", "expected 3 integers in [1, 1024]");
      s.integrator.majorant_grid = glm::ivec3(g);
    }
    i.finish();
  }
  if (r.has("background")) {
    Reader b = r.child("background");
    s.background = b.nonnegative_rgb("rgb", s.background);
    b.finish();
  }
  if (r.has("environment")) {
    Reader e = r.child("environment");
    Environment env;
    if (!e.has("file")) e.fail("file", "missing required key");
    env.file = resolve(base, e.string("file", ""));
    env.scale = e.number("scale", 1.0);
    if (env.scale < 0) e.fail("scale", "must be >= 0");
    env.rotation_deg = e.number("rotation_deg", 0.0);
    e.finish();
    s.environment = env;
  }
  if (r.has("media")) {
    const json& media = r.raw("media");
    if (!media.is_array()) r.fail("media", "expected an array");
    std::set<std::string> names;
    for (size_t k = 0; k < media.size(); ++k) {
      std::string path = "media[" + std::to_string(k) + "]";
      Medium m = read_medium(Reader(media[k], path, fname), base, static_cast<int>(k));
      if (!names.insert(m.name).second) throw input_error(fname, path + ".name", "duplicate medium name \"" + m.name + "\"");
      s.media.push_back(std::move(m));
    }
  }
  if (r.has("shapes")) {
    const json& shapes = r.raw("shapes");
    if (!shapes.is_array()) r.fail("shapes", "expected an array");
    for (size_t k = 0; k < shapes.size(); ++k)
      s.shapes.push_back(read_shape(Reader(shapes[k], "shapes[" + std::to_string(k) + "]", fname), base));
  }
  if (r.has("lights")) {
    const json& lights = r.raw("lights");
    if (!lights.is_array()) r.fail("lights", "expected an array");
    if (lights.size() > kMaxLights)
      r.fail("lights", std::to_string(lights.size()) + " lights, more than the " + std::to_string(kMaxLights) +
                           " a scene may have (every ray loops over them); merge nearby lights");
    for (size_t k = 0; k < lights.size(); ++k)
      s.lights.push_back(read_light(Reader(lights[k], "lights[" + std::to_string(k) + "]", fname)));
    if (const std::optional<IntegratorConflict> c = integrator_conflict(s.integrator, !s.lights.empty()))
      throw input_error(fname, "integrator." + c->key, c->reason);
  }
  r.finish();
  return s;
}

bool is_volume_file(const std::filesystem::path& file) {
  std::string e = file.extension().string();
  for (char& c : e) c = char(std::tolower(static_cast<unsigned char>(c)));
  return e == ".vdb" || e == ".nvdb";
}

std::string shortest_scene_text(const std::filesystem::path& volume) {
  json medium = {{"type", "vdb"}, {"file", volume.filename().string()}};
  return json{{"media", json::array({medium})}}.dump();
}

Scene load_scene(const std::filesystem::path& file) {
  std::error_code ec;
  if (is_volume_file(file)) {
    if (has_frame_pattern(file.filename().string())) {
      if (frames_on_disk(file).empty()) throw input_error(file.string(), "", "no file matches this frame pattern");
    } else if (!std::filesystem::exists(file, ec)) {
      throw input_error(file.string(), "", "no such file");
    }
    return parse_scene(shortest_scene_text(file), file);
  }
  if (!std::filesystem::exists(file, ec)) throw input_error(file.string(), "", "no such file");
  // nlohmann::json holds about ten times the text's size while parsing.
  return parse_scene(read_input_file(file, kMaxSceneBytes, "scene", 10.0), file);
}

}  // namespace pyrolume
