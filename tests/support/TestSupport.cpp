#include "support/TestSupport.h"

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <mutex>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

// Defined by the AddressSanitizer runtime, absent (null) elsewhere.
extern "C" void __asan_init() __attribute__((weak));

namespace pyrolume::test {

bool address_sanitizer() { return __asan_init != nullptr; }

const char* pyrolume_bin() {
  const char* env = std::getenv("PYROLUME_BIN");
  return env && *env ? env : PYROLUME_BIN;
}

namespace {
CliResult run_shell(const std::string& prefix, const std::string& args) {
  auto dir = temp_dir("cli");
  auto out = dir / "stdout.txt", err = dir / "stderr.txt";
  std::string cmd = prefix + std::string(pyrolume_bin()) + " " + args + " >" + out.string() + " 2>" + err.string();
  int raw = std::system(cmd.c_str());
  CliResult r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = read_file(out);
  r.err = read_file(err);
  std::filesystem::remove_all(dir);
  return r;
}
}  // namespace

CliResult run_cli(const std::string& args) { return run_shell("", args); }

CliResult run_cli_with_memory_limit(uint64_t kib, const std::string& args) {
  return run_shell("ulimit -v " + std::to_string(kib) + "; ", args);
}

namespace {
// Every folder temp_dir made, removed when the test process exits normally
// (passed or failed), so a suite run leaves nothing in /tmp; with
// PYROLUME_KEEP_TEMP=1 they stay, to look at a failure's files.
class TempDirs {
 public:
  void add(const std::filesystem::path& p) {
    std::lock_guard<std::mutex> lock(mutex_);
    dirs_.push_back(p);
  }
  ~TempDirs() {
    if (getpid() != owner_) return;  // a forked child that exits normally leaves them to its parent
    const char* keep = std::getenv("PYROLUME_KEEP_TEMP");
    if (keep && *keep && std::string(keep) != "0") return;
    for (const auto& d : dirs_) {
      std::error_code ignored;
      std::filesystem::remove_all(d, ignored);
    }
  }

 private:
  const pid_t owner_ = getpid();
  std::mutex mutex_;
  std::vector<std::filesystem::path> dirs_;
};
TempDirs& temp_dirs() {
  static TempDirs dirs;
  return dirs;
}
}  // namespace

std::filesystem::path temp_dir(const std::string& tag) {
  static std::atomic<int> counter{0};
  std::random_device rd;
  auto p = std::filesystem::temp_directory_path() /
           ("pyrolume-" + tag + "-" + std::to_string(getpid()) + "-" + std::to_string(counter++) + "-" +
            std::to_string(rd() % 100000));
  std::filesystem::remove_all(p);
  std::filesystem::create_directories(p);
  temp_dirs().add(p);
  return p;
}

void write_file(const std::filesystem::path& p, const std::string& text) {
  std::ofstream f(p, std::ios::binary);
  if (!f) throw std::runtime_error("cannot write " + p.string());
  f << text;
}

std::string read_file(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

std::filesystem::path shared_data_dir() {
  std::filesystem::path p = std::filesystem::path(PYROLUME_SHARED_DIR) / "data";
  if (const char* env = std::getenv("PYROLUME_SHARED_DATA")) p = env;
  return std::filesystem::exists(p) ? p : std::filesystem::path();
}

std::filesystem::path real_vdb_dir() {
  const std::filesystem::path data = shared_data_dir();
  return !data.empty() && std::filesystem::exists(data / "vdb") ? data / "vdb" : std::filesystem::path();
}

}  // namespace pyrolume::test
