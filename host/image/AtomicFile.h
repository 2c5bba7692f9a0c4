#pragma once
// Every file pyrolume writes goes through here (README.md "Using it";
// docs/robustness.md "Outputs"): write-then-rename, so a failed or interrupted
// run never leaves a partial file at the destination, and nothing but a
// regular file (or a missing path) is ever replaced. Usable for any output:
// images, stats JSON, CSV, checkpoints.
//
// What a destination is follows from the type of the file it leads to, never
// from where its path lies (/dev/shm is a tmpfs of regular files):
//  - missing or a regular file, wherever it lives: written to a hidden temp
//    file beside it, then renamed over it (atomic on POSIX). A symlink is
//    followed: the file it points to is replaced and the link stays.
//  - a FIFO or a character device (/dev/null, a terminal): written in place,
//    in one go, since neither can be renamed over.
//  - one of this process's descriptors (/dev/stdout, /dev/fd/N,
//    /proc/self/fd/N, directly or through symlinks), or a regular file that
//    stdout or stderr is open on (the log they were redirected into): written
//    through that descriptor at its offset, so what was printed there stays
//    and nothing is renamed over the log.
//  - anything else (a folder, a socket, a block device, a file another
//    process has open reached through /proc/PID/fd): refused.
#include <sys/types.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace pyrolume {

// Where a path leads once its symlinks are followed, and which file is there.
struct FileIdentity {
  std::filesystem::path resolved;  // absolute, symlinks followed (the path itself when missing)
  bool exists = false;
  uint64_t device = 0, inode = 0;
};
FileIdentity identify_file(const std::filesystem::path& path);

// The same file: the same device and inode when both exist (hard links and
// symlinks included), otherwise the same resolved path.
bool same_file(const FileIdentity& a, const FileIdentity& b);

// Checks, before anything is rendered, that `dest` can take an output:
// refuses (InputError "DEST: REASON") a folder, a socket, a block device, a
// symlink loop, a parent that is not a folder or cannot be written. Missing
// folders are created; each one made is appended to `created` (outermost
// first) so a caller that gives up can remove them again.
FileIdentity prepare_output(const std::filesystem::path& dest, std::vector<std::filesystem::path>* created = nullptr);

// Creates a hidden temp file ".NAME.tmp-PID-N.EXT" in the destination's folder,
// lets `write` fill it through a binary stream, flushes and fsyncs it, then
// renames it over the destination. If `write` throws or any step fails, the
// temp file is removed and the destination is left as it was. Open/write/
// rename failures and destinations that may not be replaced throw InputError
// "DEST: REASON"; an exception from `write` propagates unchanged.
void write_file_atomic(const std::filesystem::path& dest, const std::function<void(std::ostream&)>& write);

// Convenience for text outputs (stats JSON, CSV).
void write_text_atomic(const std::filesystem::path& dest, const std::string& text);

// Removes every temp file of this process that is not yet renamed into place
// (write_file_atomic's, and those an OutputCommit holds). Async-signal-safe
// (it only calls unlink): for a signal handler that exits at once, so that a
// second Ctrl-C during a save leaves no hidden ".NAME.tmp-PID-N" file behind.
void remove_pending_temp_files() noexcept;

// The outputs of one command, all or none: while an OutputCommit is alive on
// this thread, write_file_atomic (and so write_image, write_text_atomic)
// leaves each finished temp file in place, and commit() renames them all (and
// writes the FIFOs and devices). Destroyed without commit(), it removes them:
// an error while writing the second output leaves the first unwritten too.
class OutputCommit {
 public:
  OutputCommit();
  ~OutputCommit();
  OutputCommit(const OutputCommit&) = delete;
  OutputCommit& operator=(const OutputCommit&) = delete;
  // Throws InputError naming the destination whose rename or write failed
  // (those before it are in place; those after it are removed).
  void commit();

  struct Staged;  // one finished output waiting for commit()

 private:
  std::vector<Staged> staged_;
  OutputCommit* outer_;
  friend void write_file_atomic(const std::filesystem::path&, const std::function<void(std::ostream&)>&);
};

}  // namespace pyrolume
