#include "image/AtomicFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>

#include "util/Error.h"

namespace pyrolume {

namespace fs = std::filesystem;

namespace {

std::string errno_text(int e) { return e ? std::strerror(e) : "unknown error"; }

// Keep the extension last: some writers pick a format from it.
fs::path temp_path_for(const fs::path& dest) {
  static std::atomic<unsigned> counter{0};
  std::string name = "." + dest.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                     std::to_string(counter++) + dest.extension().string();
  return dest.parent_path() / name;
}

// Why the temp file could not be created, phrased about dest's folder.
std::string open_failure_reason(const fs::path& dest, int e) {
  fs::path dir = dest.parent_path().empty() ? fs::path(".") : dest.parent_path();
  std::error_code ec;
  if (e == ENOENT && !fs::exists(dir, ec)) return "cannot write: folder " + dir.string() + " does not exist";
  if (e == ENOTDIR) return "cannot write: " + dir.string() + " is not a folder";
  return "cannot write in " + dir.string() + ": " + errno_text(e);
}

}  // namespace

void write_file_atomic(const fs::path& dest, const std::function<void(std::ostream&)>& write) {
  const std::string file = dest.string();
  if (dest.filename().empty()) throw input_error(file, "", "output path names a folder, not a file");
  fs::path tmp = temp_path_for(dest);

  // O_EXCL reserves the name and gives a clean errno; the stream then reopens it.
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw input_error(file, "", open_failure_reason(dest, errno));
  ::close(fd);

  auto discard = [&] {
    std::error_code ec;
    fs::remove(tmp, ec);
  };
  try {
    {
      std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
      if (!os) throw input_error(file, "", open_failure_reason(dest, errno));
      errno = 0;
      write(os);
      os.flush();
      if (!os) throw input_error(file, "", "write failed: " + errno_text(errno));
      os.close();
      if (os.fail()) throw input_error(file, "", "write failed: " + errno_text(errno));
    }
    // fsync before rename: otherwise a crash can leave a renamed but empty file.
    int sfd = ::open(tmp.c_str(), O_RDONLY | O_CLOEXEC);
    if (sfd < 0 || ::fsync(sfd) != 0) {
      int e = errno;
      if (sfd >= 0) ::close(sfd);
      throw input_error(file, "", "write failed: " + errno_text(e));
    }
    ::close(sfd);
    std::error_code ec;
    fs::rename(tmp, dest, ec);
    if (ec) throw input_error(file, "", "cannot replace: " + ec.message());
  } catch (...) {
    discard();
    throw;
  }
}

void write_text_atomic(const fs::path& dest, const std::string& text) {
  write_file_atomic(dest, [&](std::ostream& os) { os.write(text.data(), std::streamsize(text.size())); });
}

}  // namespace pyrolume
