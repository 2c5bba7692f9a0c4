// `pyrolume denoise` on bad input: one line on stderr naming the file and the
// reason, exit status 2, no output file (and none of its temp files). All of
// these are refused before a device is opened.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "image/ImageIo.h"
#include "support/TestSupport.h"

using namespace pyrolume;
using namespace pyrolume::test;

namespace {
void expect_refused(const std::string& args, const std::filesystem::path& dir, const std::filesystem::path& out,
                    const std::string& expect) {
  const auto before = std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator());
  CliResult r = run_cli(args);
  EXPECT_EQ(r.status, 2) << args << ": " << r.err;
  EXPECT_NE(r.err.find(expect), std::string::npos) << "expected '" << expect << "' in: " << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << "one line expected: " << r.err;
  EXPECT_FALSE(std::filesystem::exists(out)) << "output written on bad input";
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), before)
      << "files left behind";
}
}  // namespace

TEST(CliDenoise, BadInputExitsTwoWithoutOutput) {
  auto dir = temp_dir("clidenoise");
  const auto out = dir / "out.exr";
  // A missing file.
  expect_refused("denoise " + (dir / "missing.exr").string() + " -o " + out.string(), dir, out, "missing.exr");
  // An EXR without variance: refused (the edge-stopping is in units of the noise).
  write_image(dir / "novar.exr", make_image(4, 4));
  expect_refused("denoise " + (dir / "novar.exr").string() + " -o " + out.string(), dir, out,
                 "novar.exr: has no variance.R/G/B channels");
  // Not an image.
  write_file(dir / "text.exr", "not an EXR");
  expect_refused("denoise " + (dir / "text.exr").string() + " -o " + out.string(), dir, out, "text.exr");
  // The output may not be the input, nor have an unknown extension.
  write_image(dir / "var.exr", make_image(4, 4, true));
  const std::string before = read_file(dir / "var.exr");
  expect_refused("denoise " + (dir / "var.exr").string() + " -o " + (dir / "var.exr").string(), dir, out, "var.exr");
  EXPECT_EQ(read_file(dir / "var.exr"), before);
  expect_refused("denoise " + (dir / "var.exr").string() + " -o " + (dir / "out.tif").string(), dir, out, "out.tif");
  std::filesystem::remove_all(dir);
}
