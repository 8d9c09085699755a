#include "hoist/io/checked_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdarg>
#include <cstring>
#include <random>
#include <utility>

namespace hoist::io {
namespace {

const char* kindOf(mode_t m) {
  if (S_ISLNK(m)) return "a symbolic link";
  if (S_ISCHR(m)) return "a character device";
  if (S_ISBLK(m)) return "a block device";
  if (S_ISFIFO(m)) return "a FIFO";
  if (S_ISSOCK(m)) return "a socket";
  if (S_ISDIR(m)) return "a directory";
  return "not a regular file";
}

std::string dirOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  if (slash == 0) return "/";
  return path.substr(0, slash);
}

std::string baseOf(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string prefix(const std::string& path, const std::string& label) {
  return label.empty() ? path : label + " " + path;
}

/// The null device itself (character device 1:3; not a symlink to it):
/// written to as a discard sink, never replaced.
bool isNullDevice(const struct stat& st) { return S_ISCHR(st.st_mode) && st.st_rdev == makedev(1, 3); }

bool isNullDevicePath(const std::string& path) {
  struct stat st{};
  return ::lstat(path.c_str(), &st) == 0 && isNullDevice(st);
}

/// "" if the target is absent, a regular file or the null device; else why
/// not (errno in `err`).
std::string targetProblem(const std::string& path, int& err) {
  struct stat st{};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT || errno == ENOTDIR) return {};  // absent (the directory check says why)
    err = errno;
    return std::string("cannot check the target: ") + std::strerror(errno);
  }
  if (S_ISREG(st.st_mode) || isNullDevice(st)) return {};
  err = S_ISDIR(st.st_mode) ? EISDIR : EEXIST;
  return std::string("exists and is ") + kindOf(st.st_mode) + "; refusing to replace it (give a regular file's path)";
}

}  // namespace

WriteError::WriteError(const std::string& path, const std::string& what, int err)
    : std::runtime_error(what), path_(path), err_(err) {}

std::string outputPathError(const std::string& path, const std::string& label) {
  if (path.empty()) return (label.empty() ? std::string("output path") : label) + ": empty path";
  if (path.back() == '/') return prefix(path, label) + ": names a directory, not a file";
  int err = 0;
  if (std::string p = targetProblem(path, err); !p.empty()) return prefix(path, label) + ": " + p;
  if (isNullDevicePath(path)) return {};
  const std::string dir = dirOf(path);
  struct stat st{};
  if (::stat(dir.c_str(), &st) != 0)
    return prefix(path, label) + ": directory " + dir + ": " + std::strerror(errno);
  if (!S_ISDIR(st.st_mode)) return prefix(path, label) + ": " + dir + " is not a directory";
  if (::access(dir.c_str(), W_OK | X_OK) != 0)
    return prefix(path, label) + ": directory " + dir + " is not writable: " + std::strerror(errno);
  return {};
}

void checkOutputPath(const std::string& path, const std::string& label) {
  if (std::string e = outputPathError(path, label); !e.empty()) throw WriteError(path, e, EINVAL);
}

CheckedFile::CheckedFile(std::string path, std::string label) : path_(std::move(path)), label_(std::move(label)) {
  if (path_.empty()) fail("empty path", ENOENT);
  int err = 0;
  if (std::string p = targetProblem(path_, err); !p.empty()) fail(p.c_str(), err);
  if (isNullDevicePath(path_)) {  // "--out /dev/null": discard the data, the node is left alone
    const int nfd = ::open(path_.c_str(), O_WRONLY | O_NOFOLLOW | O_NOCTTY | O_CLOEXEC);
    struct stat st{};
    if (nfd < 0) fail("cannot open for writing", errno);
    if (::fstat(nfd, &st) != 0 || !isNullDevice(st)) {  // swapped meanwhile
      ::close(nfd);
      fail("is no longer the null device; refusing to write to it", EEXIST);
    }
    f_ = ::fdopen(nfd, "w");
    if (f_ == nullptr) {
      const int e = errno;
      ::close(nfd);
      fail("cannot open for writing", e);
    }
    return;
  }
  // A fresh name each attempt: O_EXCL fails on anything already there (a
  // planted symlink included, which O_CREAT|O_EXCL never follows).
  static std::atomic<unsigned> counter{0};
  std::random_device rd;
  const std::string stem = dirOf(path_) + "/." + baseOf(path_) + ".tmp.";
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    char suffix[48];
    std::snprintf(suffix, sizeof suffix, "%d.%u.%08x", static_cast<int>(::getpid()), counter.fetch_add(1),
                  static_cast<unsigned>(rd()));
    tmp_ = stem + suffix;
    fd = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) {
    const int e = errno;
    tmp_.clear();
    fail(e == EEXIST ? "cannot create a temporary file next to it" : "cannot open for writing", e);
  }
  errno = 0;
  f_ = ::fdopen(fd, "w");
  if (f_ == nullptr) {
    const int e = errno;
    ::close(fd);
    fail("cannot open for writing", e);
  }
  std::setvbuf(f_, nullptr, _IOFBF, 1 << 20);
}

void CheckedFile::discard() noexcept {
  if (f_) {
    std::fclose(f_);
    f_ = nullptr;
  }
  if (!tmp_.empty()) {
    ::unlink(tmp_.c_str());
    tmp_.clear();
  }
}

CheckedFile::~CheckedFile() { discard(); }

CheckedFile::CheckedFile(CheckedFile&& o) noexcept
    : f_(std::exchange(o.f_, nullptr)),
      path_(std::move(o.path_)),
      label_(std::move(o.label_)),
      tmp_(std::exchange(o.tmp_, std::string())),
      bytes_(o.bytes_) {}

CheckedFile& CheckedFile::operator=(CheckedFile&& o) noexcept {
  if (this != &o) {
    discard();
    f_ = std::exchange(o.f_, nullptr);
    path_ = std::move(o.path_);
    label_ = std::move(o.label_);
    tmp_ = std::exchange(o.tmp_, std::string());
    bytes_ = o.bytes_;
  }
  return *this;
}

void CheckedFile::fail(const char* what, int err) {
  discard();
  std::string msg = prefix(path_, label_);
  msg += std::string(": ") + what;
  if (err != 0 && err != EEXIST && err != EISDIR) msg += std::string(": ") + std::strerror(err);
  throw WriteError(path_, msg, err != 0 ? err : EIO);
}

void CheckedFile::write(std::string_view s) {
  if (f_ == nullptr) fail("write after close", EBADF);
  errno = 0;
  if (!s.empty() && std::fwrite(s.data(), 1, s.size(), f_) != s.size()) fail("write failed", errno ? errno : EIO);
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
  if (n < 0) fail("write failed", err ? err : EIO);
  bytes_ += static_cast<std::uint64_t>(n);
}

void CheckedFile::close(bool durable) {
  if (f_ == nullptr) return;
  errno = 0;
  if (std::fflush(f_) != 0) fail("write failed", errno ? errno : EIO);
  if (std::ferror(f_)) fail("write failed", EIO);
  if (durable && !tmp_.empty() && ::fsync(::fileno(f_)) != 0) fail("fsync failed", errno ? errno : EIO);
  std::FILE* f = std::exchange(f_, nullptr);
  errno = 0;
  if (std::fclose(f) != 0) fail("close failed", errno ? errno : EIO);
  if (tmp_.empty()) return;  // the null device: nothing to rename
  // The target may have been replaced by something not ours meanwhile.
  int err = 0;
  if (std::string p = targetProblem(path_, err); !p.empty()) fail(p.c_str(), err);
  if (std::rename(tmp_.c_str(), path_.c_str()) != 0) fail("cannot rename the temporary file onto it", errno);
  tmp_.clear();
  if (durable) {  // the rename itself must reach the disk
    const int dfd = ::open(dirOf(path_).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dfd < 0 || ::fsync(dfd) != 0) {
      const int e = errno;
      if (dfd >= 0) ::close(dfd);
      throw WriteError(path_, prefix(path_, label_) + ": fsync of its directory failed: " + std::strerror(e), e);
    }
    ::close(dfd);
  }
}

void writeFileChecked(const std::string& path, std::string_view data, const std::string& label) {
  CheckedFile f(path, label);
  f.write(data);
  f.close();
}

}  // namespace hoist::io
