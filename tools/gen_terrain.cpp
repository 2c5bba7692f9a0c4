// Writes the demo's procedural mountain: DIR/mountain.obj (heightfield with uvs
// and normals) and DIR/rock.png (albedo with almost no red). Deterministic:
// the same arguments write the same bytes. See docs/surfaces.md.
//   gen_terrain [--out DIR] [--seed S] [--grid N] [--texture N]
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <string>

#include "geometry/Terrain.h"
#include "image/ImageIo.h"

int main(int argc, char** argv) {
  using namespace pyrolume;
  geometry::TerrainParams params;
  std::filesystem::path out = "assets/terrain";
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "gen_terrain: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--help" || a == "-h") {
      std::printf("usage: gen_terrain [--out DIR] [--seed S] [--grid N] [--texture N]\n");
      return 0;
    }
    try {
      if (a == "--out")
        out = value();
      else if (a == "--seed")
        params.seed = uint32_t(std::stoul(value()));
      else if (a == "--grid")
        params.grid = std::stoi(value());
      else if (a == "--texture")
        params.texture_size = std::stoi(value());
      else {
        std::fprintf(stderr, "gen_terrain: unknown argument %s\nusage: gen_terrain [--out DIR] [--seed S] [--grid N] [--texture N]\n", a.c_str());
        return 2;
      }
    } catch (const std::exception&) {
      std::fprintf(stderr, "gen_terrain: bad value for %s\n", a.c_str());
      return 2;
    }
  }
  if (params.grid < 2 || params.texture_size < 1) {
    std::fprintf(stderr, "gen_terrain: --grid must be >= 2 and --texture >= 1\n");
    return 2;
  }
  try {
    std::filesystem::create_directories(out);
    const std::string obj = geometry::terrain_obj(params);
    {
      std::ofstream f(out / "mountain.obj", std::ios::binary);
      f << obj;
      if (!f) throw std::runtime_error("cannot write " + (out / "mountain.obj").string());
    }
    write_image(out / "rock.png", geometry::terrain_albedo(params));
    std::printf("%s\n%s\n", (out / "mountain.obj").string().c_str(), (out / "rock.png").string().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gen_terrain: %s\n", e.what());
    return 1;
  }
  return 0;
}
