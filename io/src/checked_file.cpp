#include "hoist/io/checked_file.hpp"

#include <cerrno>
#include <cstdarg>
#include <cstring>
#include <utility>

namespace hoist::io {

WriteError::WriteError(const std::string& path, const std::string& what, int err)
    : std::runtime_error(what), path_(path), err_(err) {}

CheckedFile::CheckedFile(std::string path, std::string label) : path_(std::move(path)), label_(std::move(label)) {
  errno = 0;
  f_ = std::fopen(path_.c_str(), "w");
  if (f_ == nullptr) fail("cannot open for writing", errno);
  std::setvbuf(f_, nullptr, _IOFBF, 1 << 20);
}

CheckedFile::~CheckedFile() {
  if (f_) std::fclose(f_);
}

CheckedFile::CheckedFile(CheckedFile&& o) noexcept
    : f_(std::exchange(o.f_, nullptr)), path_(std::move(o.path_)), label_(std::move(o.label_)), bytes_(o.bytes_) {}

CheckedFile& CheckedFile::operator=(CheckedFile&& o) noexcept {
  if (this != &o) {
    if (f_) std::fclose(f_);
    f_ = std::exchange(o.f_, nullptr);
    path_ = std::move(o.path_);
    label_ = std::move(o.label_);
    bytes_ = o.bytes_;
  }
  return *this;
}

void CheckedFile::fail(const char* what, int err) {
  if (f_) {
    std::fclose(f_);
    f_ = nullptr;
  }
  std::string msg = label_.empty() ? path_ : label_ + " " + path_;
  msg += std::string(": ") + what + ": " + std::strerror(err != 0 ? err : EIO);
  throw WriteError(path_, msg, err != 0 ? err : EIO);
}

void CheckedFile::write(std::string_view s) {
  if (f_ == nullptr) fail("write after close", EBADF);
  errno = 0;
  if (!s.empty() && std::fwrite(s.data(), 1, s.size(), f_) != s.size()) fail("write failed", errno);
  bytes_ += s.size();
}

void CheckedFile::printf(const char* fmt, ...) {
  if (f_ == nullptr) fail("write after close", EBADF);
  std::va_list ap;
  va_start(ap, fmt);
  errno = 0;
  const int n = std::vfprintf(f_, fmt, ap);
  const int err = errno;
  va_end(ap);
  if (n < 0) fail("write failed", err);
  bytes_ += static_cast<std::uint64_t>(n);
}

void CheckedFile::close() {
  if (f_ == nullptr) return;
  errno = 0;
  if (std::fflush(f_) != 0) fail("write failed", errno);
  if (std::ferror(f_)) fail("write failed", EIO);
  std::FILE* f = std::exchange(f_, nullptr);
  errno = 0;
  if (std::fclose(f) != 0) fail("close failed", errno);
}

}  // namespace hoist::io
