// Smoke test of tools/bench (issue 8): a tiny CPU-only run must produce the CSV
// with its contract columns and a markdown report whose generated part sits
// between the bench markers, leaving hand-written text around it untouched.
// CPU backend only (references too), so the test needs no Vulkan device; the
// numbers are not checked: timings belong in benchmarks, never in tests.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "support/TestSupport.h"

namespace fs = std::filesystem;
using pyrolume::test::read_file;
using pyrolume::test::temp_dir;
using pyrolume::test::write_file;

namespace {

const char* kPython = "/usr/bin/python3";  // Debian's: the script's shebang, has matplotlib

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, sep);) out.push_back(item);
  return out;
}

}  // namespace

TEST(BenchScript, TinyCpuRunWritesCsvAndKeepsHandWrittenMarkdown) {
  if (!fs::exists(kPython)) GTEST_SKIP() << kPython << " not found";
  const fs::path script = fs::path(PYROLUME_SOURCE_DIR) / "tools" / "bench";
  ASSERT_TRUE(fs::exists(script)) << script;

  const fs::path dir = temp_dir("bench");
  // A report from an earlier run: the text outside the markers must survive.
  write_file(dir / "benchmarks.md",
             "# hand-written title\n<!-- bench:begin -->\nold numbers\n<!-- bench:end -->\nhand-written tail\n");

  const std::string cmd = std::string(kPython) + " " + script.string() + " --pyrolume " + pyrolume::test::pyrolume_bin() +
                          " --scenes homogeneous_spheres,fire --configs 'cpu*' --ref-backend cpu" +
                          " --resolution 24x16 --spp-max 2 --ref-spp 8 --reps 1 --quick --no-plot" +
                          " --data-dir " + (dir / "no-such-dir").string() + " --out-dir " + dir.string() +
                          " --work-dir " + (dir / "work").string() + " >" + (dir / "log.txt").string() + " 2>&1";
  const int raw = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << read_file(dir / "log.txt");

  // CSV: the columns, one row per render (2 scenes × 1 cpu config × spp 1,2 × 1 rep).
  const auto lines = split(read_file(dir / "benchmarks.csv"), '\n');
  ASSERT_GE(lines.size(), 5u) << read_file(dir / "log.txt");
  const std::string header = lines[0];
  for (const char* col : {"scene", "config", "backend", "device", "spp", "seconds", "rel_mse", "rmse", "bias",
                          "samples_per_second", "density_lookups_per_ray", "rep", "seed", "loadavg_1m"})
    EXPECT_NE(header.find(col), std::string::npos) << col;
  int rows = 0;
  for (size_t i = 1; i < lines.size(); ++i)
    if (!lines[i].empty()) ++rows;
  EXPECT_EQ(rows, 4);
  EXPECT_NE(read_file(dir / "benchmarks.csv").find("fire,cpu/collision,cpu"), std::string::npos);

  // Markdown: regenerated between the markers only.
  const std::string md = read_file(dir / "benchmarks.md");
  EXPECT_EQ(md.rfind("# hand-written title\n<!-- bench:begin -->", 0), 0u) << md;
  EXPECT_NE(md.find("<!-- bench:end -->\nhand-written tail\n"), std::string::npos) << md;
  EXPECT_EQ(md.find("old numbers"), std::string::npos);
  EXPECT_NE(md.find("### Efficiency at a fixed spp"), std::string::npos);
  fs::remove_all(dir);
}

// An --out-dir that cannot be made is refused at the start, in one line that
// names it, exit 2, before any render (it used to fail only when the report
// was written, after all the runs; a folder that did not exist yet failed
// the same way in --denoise mode).
TEST(BenchScript, AnOutDirThatCannotBeMadeIsRefusedBeforeTheRuns) {
  if (!fs::exists(kPython)) GTEST_SKIP() << kPython << " not found";
  const fs::path script = fs::path(PYROLUME_SOURCE_DIR) / "tools" / "bench";
  const fs::path dir = temp_dir("bench-out");
  write_file(dir / "a-file", "not a folder\n");
  const fs::path out = dir / "a-file" / "report";
  for (const char* mode : {"", " --denoise"}) {
    const std::string cmd = std::string(kPython) + " " + script.string() + " --pyrolume " +
                            pyrolume::test::pyrolume_bin() + mode + " --scenes fire --configs 'cpu*' --quick" +
                            " --out-dir " + out.string() + " --work-dir " + (dir / "work").string() + " >" +
                            (dir / "log.txt").string() + " 2>&1";
    const int raw = std::system(cmd.c_str());
    const std::string log = read_file(dir / "log.txt");
    ASSERT_TRUE(WIFEXITED(raw)) << log;
    EXPECT_EQ(WEXITSTATUS(raw), 2) << mode << ": " << log;
    EXPECT_NE(log.find("bench: --out-dir " + out.string() + ": cannot make the folder"), std::string::npos) << log;
    EXPECT_EQ(split(log, '\n').size(), 1u) << log;
    // Nothing rendered: the work folder holds no file.
    size_t files = 0;
    for (const auto& e : fs::recursive_directory_iterator(dir / "work"))
      if (e.is_regular_file()) ++files;
    EXPECT_EQ(files, 0u) << mode;
  }
  fs::remove_all(dir);
}
