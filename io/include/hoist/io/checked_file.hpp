// hoist/io/checked_file.hpp -- THE writer of every file the project writes
// (hoist-twind's --report, hoist-sim's, hoist-study's and hoist-log2csv's
// CSVs, hoist-study's figures and scripts, hoist-timing-test's report).
//
// Written to its last byte, or an error naming it: each write, the final
// fflush, ferror and fclose are checked; the first failure throws WriteError
// with the path and the errno text ("No space left on device"), so a full
// disk or an unwritable path gives exit status 1 with a message, never a
// silently truncated file.  Data goes through stdio with a 1 MiB buffer, so
// a streaming writer (hoist-sim's rows) costs one fwrite per row.
//
// Files that are not ours are never touched:
//   - the data goes to a new temporary file in the target's directory,
//     created with O_CREAT|O_EXCL|O_NOFOLLOW under a fresh random name (a
//     planted "PATH.tmp" symlink, or any other name, is never followed or
//     reused), and is renamed onto the target only by close(), when every
//     byte is written; a failed or abandoned write removes it;
//   - a target that exists and is not a regular file (a device node such
//     as /dev/full or /dev/sda, a FIFO, a socket, a directory, a symbolic
//     link) is refused when opening and again just before the rename; the
//     one exception is the null device itself (character device 1:3, e.g.
//     "--out /dev/null" to discard a run's rows), which is written to as a
//     sink and never replaced;
//   - outputPathError() checks at start-up, before any work, that the
//     target would be accepted and that its directory exists and is
//     writable, so a bad path is reported at once, not when a long run
//     ends.
#pragma once

#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <string_view>

namespace hoist::io {

class WriteError : public std::runtime_error {
 public:
  WriteError(const std::string& path, const std::string& what, int err);
  const std::string& path() const { return path_; }
  int error() const { return err_; }  ///< errno (0: none)

 private:
  std::string path_;
  int err_;
};

/// Why `path` cannot be written by CheckedFile, or "" if it can: it exists
/// and is not a regular file, or its directory is missing, not a directory
/// or not writable.  The message starts with `label` (e.g. "--report") when
/// given, then the path.  Cheap (two stat calls and an access()): call it at
/// start-up for every output path a program will write later.
std::string outputPathError(const std::string& path, const std::string& label = "");
/// outputPathError() as a throw (WriteError, error ENOTDIR/EACCES/EEXIST...).
void checkOutputPath(const std::string& path, const std::string& label = "");

class CheckedFile {
 public:
  CheckedFile() = default;
  /// Creates the temporary file for `path` (see above).  `label` (e.g.
  /// "--out") prefixes the path in error messages.  Throws WriteError if the
  /// target is refused or the temporary file cannot be created.
  explicit CheckedFile(std::string path, std::string label = "");
  ~CheckedFile();  ///< without close(): closes and removes the temporary file (an error path)
  CheckedFile(const CheckedFile&) = delete;
  CheckedFile& operator=(const CheckedFile&) = delete;
  CheckedFile(CheckedFile&& o) noexcept;
  CheckedFile& operator=(CheckedFile&& o) noexcept;

  bool isOpen() const { return f_ != nullptr; }
  /// Appends `s`; throws WriteError on the first failure.
  void write(std::string_view s);
  /// Appends printf-formatted text (vfprintf, checked); throws WriteError.
  void printf(const char* fmt, ...) __attribute__((format(printf, 2, 3)));
  /// fflush + ferror + fclose, each checked, then the rename onto the
  /// target; throws WriteError (and removes the temporary file).  `durable`:
  /// also fsync the data before the rename and the directory after it (a
  /// file that must survive a power failure, e.g. hoist-mqtt's journal).
  void close(bool durable = false);
  const std::string& path() const { return path_; }
  /// The temporary file being written ("" when none).
  const std::string& tempPath() const { return tmp_; }
  std::uint64_t bytes() const { return bytes_; }

 private:
  [[noreturn]] void fail(const char* what, int err);
  void discard() noexcept;
  std::FILE* f_ = nullptr;
  std::string path_, label_, tmp_;
  std::uint64_t bytes_ = 0;
};

/// Writes `data` to `path` through a CheckedFile (throws WriteError).
void writeFileChecked(const std::string& path, std::string_view data, const std::string& label = "");

}  // namespace hoist::io
