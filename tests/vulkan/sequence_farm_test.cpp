// docs/render-farm.md's one-machine recipe: frames spread over processes with
// `xargs -P` render the same pixels as one serial `--frames` run.
#include <sys/wait.h>

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "image/ImageIo.h"
#include "support/TestSupport.h"
#include "support/VdbScenes.h"

using namespace pyrolume;
using namespace pyrolume::test;
namespace fs = std::filesystem;

TEST(SequenceFarm, XargsParallelFramesMatchASerialRun) {
  fs::path dir = temp_dir("farm");
  for (int f = 1; f <= 3; ++f) {
    char name[32];
    std::snprintf(name, sizeof name, "puff_%04d.vdb", f);
    Lattice l;
    l.voxel = 0.1;
    write_explosion_shell_vdb(dir / name, l, 2.0 + f, 5.0 + f, 1.5f, 1500.0f + 500.0f * f, 600.0f);
  }
  write_file(dir / "s.json", R"({
    "camera": {"position": {"keys": [[1, [0, 0, -4]], [3, [0.6, 0, -4]]]}, "look_at": [0, 0, 0]},
    "film": {"width": 16, "height": 12, "spp": 4},
    "background": {"rgb": [0.3, 0.3, 0.3]},
    "media": [{"type": "vdb", "file": "puff_####.vdb", "sigma_a": [1, 1, 1], "sigma_s": [1, 1, 1], "emission": {}}]
  })");
  fs::create_directories(dir / "serial");
  fs::create_directories(dir / "farm");

  CliResult serial = run_cli("render '" + (dir / "s.json").string() + "' --frames 1-3 -o '" +
                             (dir / "serial/f_####.exr").string() + "'");
  ASSERT_EQ(serial.status, 0) << serial.err;

  // As in docs/render-farm.md: one process per frame, three at a time.
  const std::string cmd = "cd '" + dir.string() + "' && seq 1 3 | xargs -P 3 -I{} '" + std::string(test::pyrolume_bin()) +
                          "' render s.json --frames {} -o 'farm/f_####.exr' --skip-existing >farm.log 2>&1";
  int raw = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << read_file(dir / "farm.log");
  EXPECT_EQ(read_file(dir / "farm.log").find("validation"), std::string::npos) << read_file(dir / "farm.log");

  for (const char* f : {"f_0001.exr", "f_0002.exr", "f_0003.exr"}) {
    ASSERT_TRUE(fs::exists(dir / "farm" / f)) << f;
    Image a = read_image(dir / "farm" / f), b = read_image(dir / "serial" / f);
    ASSERT_EQ(a.width, b.width);
    EXPECT_EQ(a.rgb, b.rgb) << f << " differs between the farm and the serial run";
  }
  EXPECT_NE(read_image(dir / "farm/f_0001.exr").rgb, read_image(dir / "farm/f_0003.exr").rgb);
}
