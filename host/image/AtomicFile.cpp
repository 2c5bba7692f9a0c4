#include "image/AtomicFile.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <optional>
#include <sstream>

#include "util/Error.h"

namespace pyrolume {

namespace fs = std::filesystem;

namespace {

std::string errno_text(int e) { return e ? std::strerror(e) : "unknown error"; }

// The commit group of this thread, if any (OutputCommit).
thread_local OutputCommit* active_commit = nullptr;

// The temp files not yet renamed into place, for remove_pending_temp_files:
// fixed slots of plain characters, as a signal handler may read nothing else.
// A slot is free (0), being filled or emptied (1), or holds a path (2).
struct PendingTemp {
  std::atomic<int> state{0};
  char path[4096];
};
PendingTemp pending_temps[64];

void remember_temp(const fs::path& tmp) {
  const std::string& p = tmp.native();
  if (p.size() >= sizeof(PendingTemp::path)) return;  // too long to keep: left to the normal cleanup
  for (PendingTemp& slot : pending_temps) {
    int expected = 0;
    if (!slot.state.compare_exchange_strong(expected, 1)) continue;
    std::memcpy(slot.path, p.c_str(), p.size() + 1);
    slot.state.store(2);
    return;
  }
}

void forget_temp(const fs::path& tmp) {
  for (PendingTemp& slot : pending_temps) {
    if (slot.state.load() != 2 || tmp.native() != slot.path) continue;
    int expected = 2;
    if (slot.state.compare_exchange_strong(expected, 1)) slot.state.store(0);
    return;
  }
}

// Removes a temp file that will not be renamed into place.
void remove_temp(const fs::path& tmp) {
  std::error_code ec;
  fs::remove(tmp, ec);
  forget_temp(tmp);
}

// `path` with every symlink in its last component followed (up to 40 hops, as
// the kernel allows): the file that would really be written. A dangling link
// leads to the missing path it names, which is then created.
fs::path follow_symlinks(const fs::path& path) {
  fs::path p = path;
  for (int hops = 0;; ++hops) {
    std::error_code ec;
    if (!fs::is_symlink(fs::symlink_status(p, ec))) return p;
    if (hops == 40) throw input_error(path.string(), "", "too many levels of symbolic links");
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) throw input_error(path.string(), "", "cannot read the symbolic link: " + ec.message());
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
}

// What sits at a destination, and the path to write: the file a regular
// destination's symlinks lead to (renamed over, so the links stay), the path
// itself for a FIFO or device (opened, which follows the links).
enum class DestKind { Missing, Regular, Stream };
struct Dest {
  fs::path target;
  DestKind kind = DestKind::Missing;
  int fd = -1;  // a Stream that is one of this process's descriptors
};

// A descriptor named as a path: /dev/stdout, /dev/stderr, /dev/stdin,
// /dev/fd/N, /proc/self/fd/N, /proc/PID/fd/N, directly or through symlinks.
struct DescriptorLink {
  bool own = false;  // one of this process's descriptors (else another process's)
  int fd = -1;
  fs::path via;      // the spelling that named it, for messages
};

// The descriptor number in "PREFIX/N" (else -1).
int descriptor_number(const std::string& s, const std::string& prefix) {
  if (s.size() <= prefix.size() || s.size() - prefix.size() > 6 || s.compare(0, prefix.size(), prefix) != 0 ||
      s.find_first_not_of("0123456789", prefix.size()) != std::string::npos)
    return -1;
  return std::stoi(s.substr(prefix.size()));
}

// Whether one spelling (absolute, normal) names a descriptor.
std::optional<DescriptorLink> descriptor_spelling(const fs::path& p) {
  const std::string s = p.string();
  if (s == "/dev/stdin") return DescriptorLink{true, 0, p};
  if (s == "/dev/stdout") return DescriptorLink{true, 1, p};
  if (s == "/dev/stderr") return DescriptorLink{true, 2, p};
  for (const char* own : {"/dev/fd/", "/proc/self/fd/", "/proc/thread-self/fd/"})
    if (const int fd = descriptor_number(s, own); fd >= 0) return DescriptorLink{true, fd, p};
  // /proc/PID/fd/N: ours when PID is this process (/proc/self resolved).
  const std::string proc = "/proc/";
  if (s.compare(0, proc.size(), proc) != 0) return std::nullopt;
  const size_t slash = s.find('/', proc.size());
  if (slash == std::string::npos) return std::nullopt;
  const std::string pid = s.substr(proc.size(), slash - proc.size());
  if (pid.empty() || pid.size() > 9 || pid.find_first_not_of("0123456789") != std::string::npos) return std::nullopt;
  const int fd = descriptor_number(s, s.substr(0, slash) + "/fd/");
  if (fd < 0) return std::nullopt;
  return DescriptorLink{std::stol(pid) == long(::getpid()), fd, p};
}

// Whether `dest`, or a symlink on the way from it to a file, names a
// descriptor. Each step is taken as written and with its folder resolved
// (/dev/fd is itself a link to /proc/self/fd, which is /proc/PID/fd).
std::optional<DescriptorLink> descriptor_link(const fs::path& dest) {
  fs::path p = dest;
  for (int hops = 0; hops <= 40; ++hops) {
    std::error_code ec;
    const fs::path spelled = fs::absolute(p, ec).lexically_normal();
    if (auto d = descriptor_spelling(spelled)) return d;
    const fs::path folder = fs::canonical(spelled.parent_path(), ec);
    if (!ec)
      if (auto d = descriptor_spelling(folder / spelled.filename())) return d;
    if (!fs::is_symlink(fs::symlink_status(p, ec))) return std::nullopt;
    const fs::path target = fs::read_symlink(p, ec);
    if (ec) return std::nullopt;
    p = target.is_absolute() ? target : p.parent_path() / target;
  }
  return std::nullopt;  // a loop: stat reports it
}

// The standard stream (1 or 2) open for writing on the file `st` describes,
// else -1: an output that is the log stdout was redirected into.
int standard_stream_on(const struct stat& st) {
  for (int fd : {1, 2}) {
    struct stat fst {};
    const int flags = ::fcntl(fd, F_GETFL);
    if (flags < 0 || (flags & O_ACCMODE) == O_RDONLY || ::fstat(fd, &fst) != 0) continue;
    if (fst.st_dev == st.st_dev && fst.st_ino == st.st_ino) return fd;
  }
  return -1;
}

std::string file_kind(mode_t mode) {
  return S_ISSOCK(mode) ? "a socket" : S_ISBLK(mode) ? "a block device" : "not a regular file";
}

// What a destination is, decided by the type of the file it leads to (never
// by where its path lies: /dev/shm is a tmpfs of regular files):
//  - one of this process's descriptors (/dev/stdout, /proc/self/fd/1, a
//    symlink to either): written through that descriptor, at its offset, so
//    what it is open on (a terminal, a pipe, the log the shell redirected
//    into) is added to, never replaced;
//  - a regular file that stdout or stderr is open on: the same;
//  - a FIFO or character device: written in place;
//  - a regular file (or a missing one): replaced by rename;
//  - a folder, a socket, a block device, another process's open file: refused.
Dest resolve_dest(const fs::path& dest) {
  const std::string file = dest.string();
  const std::optional<DescriptorLink> link = descriptor_link(dest);
  if (link && link->own) {
    const int flags = ::fcntl(link->fd, F_GETFL);
    if (flags < 0) throw input_error(file, "", "descriptor " + std::to_string(link->fd) + " is not open");
    if ((flags & O_ACCMODE) == O_RDONLY)
      throw input_error(file, "", "descriptor " + std::to_string(link->fd) + " is open for reading only");
    struct stat st {};
    if (::fstat(link->fd, &st) == 0 && S_ISDIR(st.st_mode)) throw input_error(file, "", "is a folder, not a file");
    return {dest, DestKind::Stream, link->fd};
  }
  struct stat st {};
  if (::stat(dest.c_str(), &st) != 0) {
    const int e = errno;
    if (e != ENOENT) throw input_error(file, "", "cannot write: " + errno_text(e));
    return {follow_symlinks(dest), DestKind::Missing};  // a dangling link: the file it names is created
  }
  if (S_ISDIR(st.st_mode)) throw input_error(file, "", "is a folder, not a file");
  if (S_ISFIFO(st.st_mode) || S_ISCHR(st.st_mode)) return {dest, DestKind::Stream};
  if (!S_ISREG(st.st_mode)) throw input_error(file, "", "is " + file_kind(st.st_mode) + "; only a regular file is replaced");
  if (link)  // /proc/PID/fd/N of another process: its open file is not ours to replace
    throw input_error(file, "", "leads through " + link->via.string() +
                                    " to a file another process has open; name the file itself");
  if (const int fd = standard_stream_on(st); fd >= 0) return {dest, DestKind::Stream, fd};
  std::error_code ec;
  fs::path target = fs::canonical(dest, ec);
  if (ec) throw input_error(file, "", "cannot resolve: " + ec.message());
  return {target, DestKind::Regular};
}

// Keep the extension last: some writers pick a format from it.
fs::path temp_path_for(const fs::path& dest) {
  static std::atomic<unsigned> counter{0};
  std::string name = ".";
  name += dest.filename().string();
  name += ".tmp-" + std::to_string(::getpid()) + "-" + std::to_string(counter++);
  name += dest.extension().string();
  return dest.parent_path() / name;
}

fs::path folder_of(const fs::path& file) { return file.parent_path().empty() ? fs::path(".") : file.parent_path(); }

// Why the temp file could not be created, phrased about dest's folder.
std::string open_failure_reason(const fs::path& dest, int e) {
  const fs::path dir = folder_of(dest);
  std::error_code ec;
  if (e == ENOENT && !fs::exists(dir, ec)) return "cannot write: folder " + dir.string() + " does not exist";
  if (e == ENOTDIR) return "cannot write: " + dir.string() + " is not a folder";
  return "cannot write in " + dir.string() + ": " + errno_text(e);
}

// Writes all of `bytes` to a FIFO or device in place, or to one of this
// process's descriptors (own_fd >= 0).
void write_stream(const fs::path& dest, const fs::path& target, int own_fd, const std::string& bytes) {
  const int fd = own_fd >= 0 ? own_fd : ::open(target.c_str(), O_WRONLY | O_APPEND | O_CLOEXEC | O_NOCTTY);
  if (fd < 0) throw input_error(dest.string(), "", "cannot open for writing: " + errno_text(errno));
  auto close_it = [&] {
    if (own_fd < 0) ::close(fd);
  };
  for (size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const int e = errno;
      close_it();
      throw input_error(dest.string(), "", "write failed: " + errno_text(e));
    }
    done += size_t(n);
  }
  close_it();
}

}  // namespace

// One output finished but not yet in place: a temp file to rename over
// `target`, or (for a FIFO or device) the bytes to write into it.
struct OutputCommit::Staged {
  fs::path dest, target, tmp;
  bool stream = false;
  int fd = -1;  // a stream that is this process's descriptor
  std::string bytes;
};

FileIdentity identify_file(const fs::path& path) {
  FileIdentity id;
  std::error_code ec;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    id.exists = true;
    id.device = uint64_t(st.st_dev);
    id.inode = uint64_t(st.st_ino);
  }
  fs::path p = path;
  try {
    p = follow_symlinks(path);
  } catch (const InputError&) {
  }
  id.resolved = fs::weakly_canonical(fs::absolute(p, ec), ec);
  if (ec) id.resolved = fs::absolute(p, ec).lexically_normal();
  return id;
}

bool same_file(const FileIdentity& a, const FileIdentity& b) {
  if (a.exists && b.exists) return a.device == b.device && a.inode == b.inode;
  return a.resolved == b.resolved;
}

FileIdentity prepare_output(const fs::path& dest, std::vector<fs::path>* created) {
  const std::string file = dest.string();
  if (dest.filename().empty() || dest.filename() == "." || dest.filename() == "..")
    throw input_error(file, "", "names a folder, not a file");
  const auto [target, kind, fd] = resolve_dest(dest);
  if (kind == DestKind::Stream) {
    if (fd < 0 && ::access(target.c_str(), W_OK) != 0) throw input_error(file, "", "cannot write: " + errno_text(errno));
    return identify_file(dest);
  }
  // A regular file or a missing one: its folder must exist (made here) and
  // take the temp file the rename needs.
  const fs::path dir = folder_of(target);
  std::error_code ec;
  if (!fs::exists(dir, ec)) {
    std::vector<fs::path> missing;  // innermost first
    for (fs::path d = dir; !d.empty() && !fs::exists(d, ec); d = d.parent_path()) {
      missing.push_back(d);
      if (d == d.parent_path()) break;
    }
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
      if (!fs::create_directory(*it, ec) && ec)
        throw input_error(file, "", "cannot create the folder " + it->string() + ": " + ec.message());
      if (created && it->filename() != "." && it->filename() != "..") created->push_back(*it);
    }
  } else if (!fs::is_directory(dir, ec)) {
    throw input_error(file, "", "cannot write: " + dir.string() + " is not a folder");
  }
  // A probe file: permissions, read-only mounts and ACLs all answer here, as
  // they will for the temp file after the render.
  const fs::path probe = temp_path_for(target);
  const int probe_fd = ::open(probe.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (probe_fd < 0) throw input_error(file, "", open_failure_reason(target, errno));
  ::close(probe_fd);
  ::unlink(probe.c_str());
  return identify_file(dest);
}

void write_file_atomic(const fs::path& dest, const std::function<void(std::ostream&)>& write) {
  const std::string file = dest.string();
  if (dest.filename().empty()) throw input_error(file, "", "output path names a folder, not a file");
  const auto [target, kind, own_fd] = resolve_dest(dest);
  OutputCommit* group = active_commit;

  if (kind == DestKind::Stream) {
    std::ostringstream os(std::ios::binary);
    write(os);
    OutputCommit::Staged s{dest, target, {}, true, own_fd, std::move(os).str()};
    if (group) group->staged_.push_back(std::move(s));
    else write_stream(dest, target, own_fd, s.bytes);
    return;
  }

  fs::path tmp = temp_path_for(target);
  // O_EXCL reserves the name and gives a clean errno; the stream then reopens it.
  int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
  if (fd < 0) throw input_error(file, "", open_failure_reason(target, errno));
  ::close(fd);
  remember_temp(tmp);

  try {
    {
      std::ofstream os(tmp, std::ios::binary | std::ios::trunc);
      if (!os) throw input_error(file, "", open_failure_reason(target, errno));
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
    if (group) {
      group->staged_.push_back(OutputCommit::Staged{dest, target, tmp, false, -1, {}});
      return;
    }
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) throw input_error(file, "", "cannot replace: " + ec.message());
    forget_temp(tmp);
  } catch (...) {
    remove_temp(tmp);
    throw;
  }
}

void write_text_atomic(const fs::path& dest, const std::string& text) {
  write_file_atomic(dest, [&](std::ostream& os) { os.write(text.data(), std::streamsize(text.size())); });
}

OutputCommit::OutputCommit() : outer_(active_commit) { active_commit = this; }

OutputCommit::~OutputCommit() {
  active_commit = outer_;
  for (const Staged& s : staged_)
    if (!s.stream) remove_temp(s.tmp);
}

void OutputCommit::commit() {
  active_commit = outer_;  // from here on writes go straight to their files
  std::vector<Staged> staged = std::move(staged_);
  staged_.clear();
  for (size_t i = 0; i < staged.size(); ++i) {
    const Staged& s = staged[i];
    try {
      if (s.stream) {
        write_stream(s.dest, s.target, s.fd, s.bytes);
        continue;
      }
      std::error_code ec;
      fs::rename(s.tmp, s.target, ec);
      if (ec) throw input_error(s.dest.string(), "", "cannot replace: " + ec.message());
      forget_temp(s.tmp);
    } catch (...) {
      for (size_t j = i; j < staged.size(); ++j)
        if (!staged[j].stream) remove_temp(staged[j].tmp);
      throw;
    }
  }
}

void remove_pending_temp_files() noexcept {
  for (PendingTemp& slot : pending_temps)
    if (slot.state.load() == 2) ::unlink(slot.path);
}

}  // namespace pyrolume
