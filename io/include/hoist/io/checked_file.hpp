// hoist/io/checked_file.hpp -- an output file written to its last byte, or
// an error naming it.
//
// Every file a program writes is checked (issue 12, section 6): each write,
// the final fflush, ferror and fclose; the first failure throws WriteError
// with the path and the errno text ("No space left on device"), so a full
// disk or an unwritable path gives exit status 1 with a message, never a
// silently truncated file.  Data goes through stdio with a 1 MiB buffer, so
// a streaming writer (hoist-sim's rows) costs one fwrite per row.
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

class CheckedFile {
 public:
  CheckedFile() = default;
  /// Opens `path` for writing (truncates).  `label` (e.g. "--out") prefixes
  /// the path in error messages.  Throws WriteError if it cannot be opened.
  explicit CheckedFile(std::string path, std::string label = "");
  ~CheckedFile();  ///< closes, unchecked, if close() was not called (an error path)
  CheckedFile(const CheckedFile&) = delete;
  CheckedFile& operator=(const CheckedFile&) = delete;
  CheckedFile(CheckedFile&& o) noexcept;
  CheckedFile& operator=(CheckedFile&& o) noexcept;

  bool isOpen() const { return f_ != nullptr; }
  /// Appends `s`; throws WriteError on the first failure.
  void write(std::string_view s);
  /// Appends printf-formatted text (vfprintf, checked); throws WriteError.
  void printf(const char* fmt, ...) __attribute__((format(printf, 2, 3)));
  /// fflush + ferror + fclose, each checked; throws WriteError.
  void close();
  const std::string& path() const { return path_; }
  std::uint64_t bytes() const { return bytes_; }

 private:
  [[noreturn]] void fail(const char* what, int err);
  std::FILE* f_ = nullptr;
  std::string path_, label_;
  std::uint64_t bytes_ = 0;
};

}  // namespace hoist::io
