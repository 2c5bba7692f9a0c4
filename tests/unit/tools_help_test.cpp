// Every tool answers --help: its usage on stdout, exit status 0, and nothing
// written where it runs (gen_sky once wrote an EXR named "--help").
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <sys/wait.h>

#include "support/TestSupport.h"

namespace fs = std::filesystem;
using namespace pyrolume::test;

TEST(ToolsHelp, EveryToolAnswersHelpWritesNothingAndExitsZero) {
  const fs::path bin = fs::path(pyrolume_bin()).parent_path(), tools = fs::path(PYROLUME_SOURCE_DIR) / "tools";
  // The C++ tools are not built in the sanitizer build; the scripts always exist.
  std::vector<fs::path> list = {tools / "demo",     tools / "test",   tools / "fuzz",
                                tools / "sanitize", tools / "encode", tools / "gen_cie_tables",
                                tools / "gen_explosion_sequence",     tools / "bench",
                                tools / "readme_images",              tools / "cycles/compare_blender_fire",
                                tools / "cycles/compare_views"};
  int built = 0;
  for (const char* name : {"gen_sky", "gen_fire_vdb", "gen_terrain", "bench_mis", "bench_lookup"})
    if (fs::exists(bin / name)) list.push_back(bin / name), ++built;
  if (built == 0) std::printf("C++ tools not built here (sanitizer build): only the scripts are checked\n");
  for (const fs::path& tool : list) {
    const fs::path dir = temp_dir("help");
    const std::string cmd = "cd '" + dir.string() + "' && '" + tool.string() + "' --help >'" + (dir / "out").string() +
                            "' 2>'" + (dir / "err").string() + "'";
    const int raw = std::system(cmd.c_str());
    const std::string out = read_file(dir / "out"), err = read_file(dir / "err");
    EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << tool << "\n" << err;
    EXPECT_GT(out.size(), 20u) << tool << ": no usage on stdout\n" << err;
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir)) files += e.path().filename() != "out" && e.path().filename() != "err";
    EXPECT_EQ(files, 0) << tool << " wrote a file";
    fs::remove_all(dir);
  }
}

// A bad argument: exit status 2, nothing written, and a line on stderr that
// names it (docs: bad input gets a one-line error naming the key).
TEST(ToolsHelp, EveryCppToolNamesABadArgumentAndExitsTwo) {
  const fs::path bin = fs::path(pyrolume_bin()).parent_path();
  struct Case {
    std::vector<std::string> args;  // tool, then its arguments
    std::string named;              // what stderr must name
  };
  const std::vector<Case> cases = {{{"gen_sky", "out.exr", "--bogus-flag"}, "--bogus-flag"},
                                   {{"gen_sky", "out.exr", "--width", "x7"}, "--width"},
                                   {{"gen_fire_vdb", "out.vdb", "--bogus-flag"}, "--bogus-flag"},
                                   {{"gen_fire_vdb", "out.vdb", "--resolution"}, "--resolution"},
                                   {{"gen_terrain", "--bogus-flag"}, "--bogus-flag"},
                                   {{"gen_terrain", "--grid", "seven"}, "--grid"},
                                   {{"bench_mis", "--bogus-flag"}, "--bogus-flag"},
                                   {{"bench_lookup", "--bogus-flag"}, "--bogus-flag"},
                                   {{"bench_lookup", "--steps", "0"}, "--steps"}};
  for (const Case& c : cases) {
    if (!fs::exists(bin / c.args[0])) continue;  // the sanitizer build has no C++ tools
    const fs::path dir = temp_dir("badarg");
    std::string cmd = "cd '" + dir.string() + "' && '" + (bin / c.args[0]).string() + "'";
    for (size_t i = 1; i < c.args.size(); ++i) cmd += " '" + c.args[i] + "'";
    cmd += " >'" + (dir / "out").string() + "' 2>'" + (dir / "err").string() + "'";
    const int raw = std::system(cmd.c_str());
    const std::string err = read_file(dir / "err"), &bad = c.named;
    EXPECT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 2) << cmd << "\n" << err;
    EXPECT_NE(err.find(bad), std::string::npos) << cmd << ": stderr does not name " << bad << ":\n" << err;
    int files = 0;
    for (const auto& e : fs::directory_iterator(dir)) files += e.path().filename() != "out" && e.path().filename() != "err";
    EXPECT_EQ(files, 0) << cmd << " wrote a file";
    fs::remove_all(dir);
  }
}
