// On a terminal, `pyrolume render` says what it is doing while the scene
// loads (a large grid takes seconds), then draws its progress bar, and clears
// the line when it is done; off a terminal (pipes, logs) it draws nothing.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <string>
#include <vector>

#include "support/TestSupport.h"

namespace fs = std::filesystem;
using namespace pyrolume::test;

namespace {

// Runs argv with stderr on a pseudo-terminal (stdout to /dev/null); returns
// what was drawn there and the exit status.
std::string stderr_on_terminal(const std::vector<std::string>& argv, int& status) {
  const int master = posix_openpt(O_RDWR | O_NOCTTY);
  if (master < 0 || grantpt(master) != 0 || unlockpt(master) != 0) return "no pty";
  const std::string name = ptsname(master);
  // Held open here too, so the terminal lives until everything is read.
  const int slave = open(name.c_str(), O_RDWR | O_NOCTTY);
  const pid_t pid = fork();
  if (pid == 0) {
    const int devnull = open("/dev/null", O_WRONLY);
    dup2(slave, 2);
    dup2(devnull, 1);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execv(args[0], args.data());
    _exit(127);
  }
  // The output is a few hundred bytes, far below the terminal's buffer, so
  // the child never waits for us to read.
  waitpid(pid, &status, 0);
  fcntl(master, F_SETFL, O_NONBLOCK);
  std::string out;
  char buf[4096];
  for (;;) {
    const ssize_t n = read(master, buf, sizeof buf);
    if (n <= 0) break;
    out.append(buf, size_t(n));
  }
  close(slave);
  close(master);
  return out;
}

}  // namespace

TEST(CliProgress, TerminalShowsLoadingThenTheBarAndClearsTheLine) {
  const fs::path dir = temp_dir("progress");
  const fs::path out = dir / "fire.exr";
  int status = -1;
  const std::string drawn =
      stderr_on_terminal({pyrolume_bin(), "render", std::string(PYROLUME_SOURCE_DIR) + "/assets/scenes/fire.json", "-o",
                          out.string(), "--backend", "cpu", "--spp", "4", "--width", "16", "--height", "9"},
                         status);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << drawn;
  EXPECT_TRUE(fs::exists(out));
  const size_t loading = drawn.find("rendering: loading the scene's volumes, lights and shaders ...");
  const size_t bar = drawn.find("\r\033[Krendering [");
  ASSERT_NE(loading, std::string::npos) << drawn;
  ASSERT_NE(bar, std::string::npos) << drawn;
  EXPECT_LT(loading, bar) << drawn;
  EXPECT_NE(drawn.find("100.0%", bar), std::string::npos) << drawn;
  // The last thing drawn clears the line: the shell's prompt starts clean.
  const std::string clear = "\r\033[K";
  ASSERT_GE(drawn.size(), clear.size());
  EXPECT_EQ(drawn.substr(drawn.size() - clear.size()), clear) << drawn;
  fs::remove_all(dir);
}

TEST(CliProgress, NothingIsDrawnOffATerminal) {
  const fs::path dir = temp_dir("progress_pipe");
  const std::string cmd = std::string(pyrolume_bin()) + " render '" + PYROLUME_SOURCE_DIR +
                          "/assets/scenes/fire.json' -o '" + (dir / "fire.exr").string() +
                          "' --backend cpu --spp 4 --width 16 --height 9 >/dev/null 2>'" + (dir / "err").string() + "'";
  const int raw = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 0) << read_file(dir / "err");
  const std::string err = read_file(dir / "err");
  EXPECT_EQ(err.find("loading"), std::string::npos) << err;
  EXPECT_EQ(err.find('\r'), std::string::npos) << err;
  fs::remove_all(dir);
}
