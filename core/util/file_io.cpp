// file_io.cpp — whole-file reads and atomic whole-file writes (POSIX).
//
// The atomic write is the classic "write a temporary file, fsync, rename over the
// target" sequence: rename() within one directory replaces the name atomically, so an
// interrupted run or a full disk never leaves a truncated plant file behind.
#include "core/util/file_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <system_error>

namespace sylva {
namespace {

Diagnostic errno_error(const std::string& path, const std::string& what, int error_number) {
  return file_diagnostic(path, what + ": " + std::generic_category().message(error_number), error_number);
}

// Keeps the temporary name within NAME_MAX (255) however long the target's name is.
constexpr size_t kMaxNameInTemporary = 200;

// write() may write less than asked (signals, pipes, RLIMIT_FSIZE); loop until done.
bool write_all(int fd, std::string_view bytes) {
  size_t written = 0;
  while (written < bytes.size()) {
    const size_t chunk = std::min<size_t>(bytes.size() - written, size_t{1} << 30);
    const ssize_t n = ::write(fd, bytes.data() + written, chunk);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    if (n == 0) {
      errno = EIO;
      return false;
    }
    written += static_cast<size_t>(n);
  }
  return true;
}

}  // namespace

Expected<std::string> read_text_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error_number = errno;  // before anything that may allocate
    return errno_error(path, "cannot open for reading", error_number);
  }

  struct stat info {};
  if (::fstat(fd, &info) != 0) {
    const int error_number = errno;
    ::close(fd);
    return errno_error(path, "cannot read", error_number);
  }
  if (S_ISDIR(info.st_mode)) {
    ::close(fd);
    return errno_error(path, "cannot read", EISDIR);
  }

  std::string contents;
  if (S_ISREG(info.st_mode) && info.st_size > 0) contents.reserve(static_cast<size_t>(info.st_size));
  char buffer[1 << 16];
  for (;;) {  // to end of file, not to st_size: the file may change, /proc files have none
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n == 0) break;
    if (n < 0) {
      if (errno == EINTR) continue;
      const int error_number = errno;
      ::close(fd);
      return errno_error(path, "cannot read", error_number);
    }
    contents.append(buffer, static_cast<size_t>(n));
  }
  ::close(fd);
  return contents;
}

Status write_file_atomically(const std::string& path, std::string_view bytes) {
  if (path.empty()) return file_diagnostic(path, "cannot write: the path is empty");
  if (path.back() == '/') return errno_error(path, "cannot write", EISDIR);

  const size_t slash = path.rfind('/');
  const std::string directory_prefix = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string directory = slash == std::string::npos ? "."
                                : slash == 0               ? "/"
                                                           : path.substr(0, slash);
  const std::string name = path.substr(directory_prefix.size());

  // Keep the permission bits (not set-user/group-ID) of the file being replaced.
  struct stat existing {};
  const bool replaces_regular_file = ::lstat(path.c_str(), &existing) == 0 && S_ISREG(existing.st_mode);

  static std::atomic<uint64_t> counter{0};
  std::string temporary;
  int fd = -1;
  for (int attempt = 0; attempt < 100 && fd < 0; ++attempt) {
    temporary = directory_prefix + "." + name.substr(0, kMaxNameInTemporary) + ".tmp-" +
                std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1));
    fd = ::open(temporary.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) {
    const int error_number = errno;
    return errno_error(path, "cannot create a temporary file in directory '" + directory + "'",
                       error_number);
  }

  // `error_number` is errno read right after the failing call, before any allocation.
  auto fail = [&](int error_number, const char* what, const char* after_name) {
    if (fd >= 0) ::close(fd);
    ::unlink(temporary.c_str());
    return errno_error(path, std::string(what) + " '" + temporary + "'" + after_name, error_number);
  };

  if (replaces_regular_file) (void)::fchmod(fd, existing.st_mode & 0777);  // before any data
  if (!write_all(fd, bytes)) return fail(errno, "cannot write temporary file", "");
  if (::fsync(fd) != 0) return fail(errno, "cannot flush temporary file", " to disk");
  const int closed = ::close(fd);
  fd = -1;
  if (closed != 0) return fail(errno, "cannot close temporary file", "");
  if (::rename(temporary.c_str(), path.c_str()) != 0) {
    return fail(errno, "cannot rename temporary file", " over it");
  }

  // Make the rename itself durable; the data is already safe, so failure here is not
  // reported (some file systems refuse fsync on directories).
  const int directory_fd = ::open(directory.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (directory_fd >= 0) {
    (void)::fsync(directory_fd);
    ::close(directory_fd);
  }
  return {};
}

}  // namespace sylva
