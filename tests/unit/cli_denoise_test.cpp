// `pyrolume denoise` on bad input: one line on stderr naming the file and the
// reason, exit status 2, no output file (and none of its temp files). All of
// these are refused before a device is opened.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <filesystem>

#include "image/ImageIo.h"
#include "support/AccumulationScenes.h"
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

// The edge-stopping width divides differences: a NaN, an infinity, 0, a
// negative value or one past single precision would write NaN (or filter
// nothing). CLI11's PositiveNumber let "nan" through.
TEST(CliDenoise, SigmaMustBeFiniteAndPositive) {
  auto dir = temp_dir("clidenoise-sigma");
  const auto out = dir / "out.exr";
  write_image(dir / "var.exr", make_image(4, 4, true));
  for (const char* v : {"nan", "NaN", "inf", "-inf", "0", "-1", "1e39", "1e-50", "x"})
    expect_refused("denoise " + (dir / "var.exr").string() + " -o " + out.string() + " --sigma-l " + v, dir, out,
                   "--sigma-l");
  std::filesystem::remove_all(dir);
}

// SIGTERM (143) and SIGINT (130) end `denoise` with nothing written, as they
// end `render`. The input is a FIFO, so the signal arrives at a known point:
// pyrolume opens it only after its handlers are installed and its output is
// checked, and reads the image only after the signal (the writer sends it
// first). With the fix the command stops before the device opens; without it
// the image was denoised and written, exit 0.
TEST(CliDenoise, SignalEndsItWithNothingWritten) {
  for (const auto& [sig, status] : {std::pair{SIGTERM, 143}, std::pair{SIGINT, 130}}) {
    SCOPED_TRACE(sig == SIGTERM ? "SIGTERM" : "SIGINT");
    auto dir = temp_dir("clidenoise-signal");
    const auto out = dir / "out.exr", fifo = dir / "in.exr";
    write_image(dir / "var.exr", make_image(4, 4, true));
    const std::string bytes = read_file(dir / "var.exr");
    std::filesystem::remove(dir / "var.exr");
    ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
    CliProcess p = start_cli({"denoise", fifo.string(), "-o", out.string()}, dir);
    // Non-blocking: open fails (ENXIO) until the reader has the FIFO open.
    int fd = -1;
    while ((fd = open(fifo.c_str(), O_WRONLY | O_NONBLOCK)) < 0) {
      int raw = 0;
      ASSERT_EQ(waitpid(p.pid, &raw, WNOHANG), 0) << "ended before reading its input: " << read_file(p.err);
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) & ~O_NONBLOCK);
    kill(p.pid, sig);
    ASSERT_EQ(write(fd, bytes.data(), bytes.size()), ssize_t(bytes.size()));
    close(fd);
    EXPECT_EQ(wait_exit(p), status) << read_file(p.err);
    EXPECT_FALSE(std::filesystem::exists(out));
    // Nothing else either (no temp file): the FIFO and the two logs.
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), std::filesystem::directory_iterator()), 3);
    std::filesystem::remove_all(dir);
  }
}
