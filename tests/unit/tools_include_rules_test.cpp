// tools/check_includes.py (ctest include_rules) can fail: on a small tree of
// its own, a "never reaches" rule naming a system header catches a folder
// that reaches it through another folder's header, and passes once the
// header no longer includes it (docs/architecture.md).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <sys/wait.h>

#include "support/TestSupport.h"

namespace fs = std::filesystem;

namespace {

void write_text(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

// Exit status of the checker on `root`; its output goes to `out`.
int check_includes(const fs::path& root, const fs::path& out) {
  const std::string cmd = "/usr/bin/python3 '" + (fs::path(PYROLUME_SOURCE_DIR) / "tools/check_includes.py").string() +
                          "' '" + root.string() + "' >'" + out.string() + "' 2>&1";
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST(IncludeRules, NeverReachesASystemHeaderThroughAnotherFolder) {
  const fs::path root = pyrolume::test::temp_dir("include-rules");
  write_text(root / "docs/architecture.md",
             "- `host/util` may include (nothing)\n"
             "- `host/gpu` may include `host/util`\n"
             "- `host/cli` may include `host/gpu`, `host/util`\n"
             "- `host/cli` never reaches `<vulkan/`\n");
  write_text(root / "host/cli/main.cpp", "#include \"gpu/Api.h\"\n#include <string>\n");
  write_text(root / "host/gpu/Api.h", "#pragma once\n#include \"gpu/Device.h\"\n");
  write_text(root / "host/gpu/Device.h", "#pragma once\n#include <vulkan/vulkan.h>\n");
  const fs::path out = root / "out.txt";

  EXPECT_EQ(check_includes(root, out), 1);
  const std::string said = pyrolume::test::read_file(out);
  EXPECT_NE(said.find("host/cli never reaches <vulkan/, but host/cli/main.cpp -> host/gpu/Api.h -> "
                      "host/gpu/Device.h -> <vulkan/vulkan.h>"),
            std::string::npos)
      << said;

  write_text(root / "host/gpu/Device.h", "#pragma once\n#include <cstdint>\n");
  EXPECT_EQ(check_includes(root, out), 0) << pyrolume::test::read_file(out);
}
