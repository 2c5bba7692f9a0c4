#include "util/InputFile.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "util/Error.h"
#include "util/Memory.h"

namespace pyrolume {

namespace {

// Closes the descriptor on every path out.
struct Fd {
  int fd = -1;
  ~Fd() {
    if (fd >= 0) ::close(fd);
  }
};

}  // namespace

std::string read_input_file(const std::filesystem::path& file, uint64_t max_bytes, const std::string& what,
                            double memory_factor) {
  const std::string name = file.string();
  Fd f;
  f.fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (f.fd < 0) {
    throw input_error(name, "", std::string("cannot open: ") + std::strerror(errno));
  }
  struct stat st {};
  if (::fstat(f.fd, &st) != 0) throw input_error(name, "", std::string("cannot be read: ") + std::strerror(errno));
  if (S_ISDIR(st.st_mode)) throw input_error(name, "", "is a directory, not a file");
  const bool regular = S_ISREG(st.st_mode);
  const uint64_t size = regular ? uint64_t(st.st_size) : 0;
  auto too_large = [&](uint64_t at_least) {
    const std::string limit = "the limit for " + what + " files (" + format_bytes(max_bytes) + ")";
    if (!regular) return input_error(name, "", "is not a regular file and gives more than " + limit);
    return input_error(name, "", "is " + format_bytes(at_least) + ", larger than " + limit);
  };
  if (regular && size > max_bytes) throw too_large(size);
  if (regular) require_memory(name, "", "reading this " + what + " file", uint64_t(double(size) * memory_factor));

  std::string bytes;
  bytes.reserve(size_t(size));
  char chunk[1 << 16];
  for (;;) {
    const ssize_t n = ::read(f.fd, chunk, sizeof chunk);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw input_error(name, "", std::string("cannot be read: ") + std::strerror(errno));
    }
    if (n == 0) break;
    if (bytes.size() + size_t(n) > max_bytes) throw too_large(bytes.size() + size_t(n));
    // A stream has no size to check first: check memory as it grows.
    if (!regular && bytes.size() + size_t(n) > bytes.capacity())
      require_memory(name, "", "reading this " + what + " stream",
                     uint64_t(double(2 * (bytes.size() + size_t(n))) * memory_factor));
    bytes.append(chunk, size_t(n));
  }
  return bytes;
}

}  // namespace pyrolume
